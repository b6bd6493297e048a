#include <QCheckBox>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QSpinBox>

#include "step_pages.h"

namespace cranioplan::gui {

SmoothPage::SmoothPage(PageHost& host) : StepPage(8, host) {
  radius_ = new QSlider(Qt::Horizontal, this);
  radius_->setObjectName("smoothRadius");
  radius_->setRange(2, 40);
  radius_->setValue(10);
  weight_ = new QSlider(Qt::Horizontal, this);
  weight_->setObjectName("smoothWeight");
  weight_->setRange(1, 10);
  weight_->setValue(2);
  iterations_ = new QSpinBox(this);
  iterations_->setRange(1, 20);
  project_ = new QCheckBox(tr("Put smoothed markers back on the mirror"), this);
  project_->setChecked(true);
  info_ = new QLabel(this);
  info_->setWordWrap(true);
  for (QSlider* s : {radius_, weight_})
    connect(s, &QSlider::valueChanged, this, &SmoothPage::preview);
  connect(iterations_, &QSpinBox::valueChanged, this, &SmoothPage::preview);
  form_->addRow(tr("Radius"), radius_);
  form_->addRow(tr("Edge-marker weight"), weight_);
  form_->addRow(tr("Iterations"), iterations_);
  form_->addRow(project_);
  QPushButton* apply = add_button(tr("Apply smoothing"), "applySmoothing");
  connect(apply, &QPushButton::clicked, this,
          [this] { host_.push(smooth_command(), tr("Smoothing")); });
  form_->addRow(info_);
}

Command SmoothPage::smooth_command() const {
  return commands::smooth_markers({static_cast<double>(radius_->value()),
                                   static_cast<double>(weight_->value()), iterations_->value()},
                                  project_->isChecked());
}

void SmoothPage::preview() {
  if (!host_.plan().implant) return;
  info_->setText(tr("Radius %1 mm, edge weight %2 — preview (Apply to keep it)")
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
