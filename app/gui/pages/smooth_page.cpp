#include <QCheckBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QSpinBox>

#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "declared_fields.h"
#include "step_pages.h"

namespace cranioplan::gui {

SmoothPage::SmoothPage(PageHost& host) : StepPage(kSmoothStep, host) {
  const SmoothParams defaults;
  radius_ = declared_slider(this, "smoothRadius", spec_of<SmoothParams>("radius_mm"),
                            static_cast<int>(defaults.radius_mm));
  weight_ = declared_slider(this, "smoothWeight", spec_of<SmoothParams>("edge_weight"),
                            static_cast<int>(defaults.edge_weight));
  iterations_ = declared_count(this, "smoothIterations", spec_of<SmoothParams>("iterations"),
                               defaults.iterations);
  project_ = new QCheckBox(tr("Put smoothed markers back on the mirror"), this);
  project_->setChecked(true);
  info_ = new QLabel(this);
  info_->setWordWrap(true);
  for (QSlider* s : {radius_, weight_})
    connect(s, &QSlider::valueChanged, this, &SmoothPage::preview);
  connect(iterations_, &QSpinBox::valueChanged, this, &SmoothPage::preview);
  // Each slider with its value beside it.
  const auto with_value = [this](QSlider* slider, QLabel*& value, const char* name) {
    value = new QLabel(this);
    value->setObjectName(name);
    value->setMinimumWidth(value->fontMetrics().horizontalAdvance(QStringLiteral("100 mm")));
    auto* row = new QHBoxLayout;
    row->addWidget(slider, 1);
    row->addWidget(value);
    return row;
  };
  form_->addRow(tr("Radius"), with_value(radius_, radius_value_, "smoothRadiusValue"));
  form_->addRow(tr("Edge-marker weight"), with_value(weight_, weight_value_, "smoothWeightValue"));
  const auto show_values = [this] {
    radius_value_->setText(tr("%1 mm").arg(radius_->value()));
    weight_value_->setText(QString::number(weight_->value()));
  };
  for (QSlider* s : {radius_, weight_}) connect(s, &QSlider::valueChanged, this, show_values);
  show_values();
  form_->addRow(tr("Iterations"), iterations_);
  form_->addRow(project_);
  QPushButton* apply = add_button(tr("Apply smoothing"), "applySmoothing");
  connect(apply, &QPushButton::clicked, this, [this] {
    applying_ = true;
    host_.push(smooth_command(), tr("Smoothing"));
    info_->setText(tr("Applied: radius %1 mm, edge weight %2, %3 iterations (Edit → Undo takes "
                      "it back).")
                       .arg(radius_->value())
                       .arg(weight_->value())
                       .arg(iterations_->value()));
  });
  form_->addRow(info_);
}

Command SmoothPage::smooth_command() const {
  return commands::smooth_markers({static_cast<double>(radius_->value()),
                                   static_cast<double>(weight_->value()), iterations_->value()},
                                  project_->isChecked());
}

void SmoothPage::show_state(const PlanState& s) {
  if (applying_) {
    applying_ = false;
    applied_ = s.implant.get();
    return;
  }
  if (s.implant.get() != applied_ && info_->text().startsWith(tr("Applied"))) info_->clear();
}

void SmoothPage::preview() {
  if (!host_.plan().implant) return;
  info_->setText(tr("Preview of radius %1 mm, edge weight %2: Apply smoothing keeps it.")
                     .arg(radius_->value())
                     .arg(weight_->value()));
  if (auto state = host_.preview(smooth_command())) host_.view().show_state(*state);
}

void SmoothPage::surface_clicked(const Eigen::Vector3d& p) {
  host_.push(commands::add_marker(host_.marker_type(), p));
}

SkullView::PickTarget SmoothPage::pick_target() const {
  return marker_pick_target(host_.marker_type());
}

QString SmoothPage::keys_hint() const { return marker_keys_hint(); }

}  // namespace cranioplan::gui
