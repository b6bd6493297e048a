#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QVBoxLayout>

#include "step_pages.h"

namespace cranioplan::gui {

MirrorPage::MirrorPage(PageHost& host) : StepPage(kMirrorStep, host) {
  QPushButton* mirror = add_button(tr("Mirror skull"), "mirror");
  connect(mirror, &QPushButton::clicked, this,
          [this] { host_.push(commands::mirror(), tr("Mirroring")); });
  roi_only_ = new QCheckBox(tr("Only around a point (click the skull)"), this);
  roi_only_->setObjectName("roiOnly");
  roi_radius_ = new QDoubleSpinBox(this);
  roi_radius_->setRange(20, 200);
  roi_radius_->setValue(70);
  roi_radius_->setSuffix(" mm");
  form_->addRow(roi_only_);
  form_->addRow(tr("Region radius"), roi_radius_);
  QPushButton* reg = add_button(tr("Register"), "register");
  connect(reg, &QPushButton::clicked, this, [this] {
    RegisterParams params;
    if (roi_only_->isChecked() && roi_center_) {
      RegionOfInterest roi;
      roi.center = *roi_center_;
      roi.radius = roi_radius_->value();
      params.roi = roi;
    }
    host_.push(commands::register_mirror(params), tr("Registering"));
  });
  register_info_ = new QLabel(this);
  register_info_->setWordWrap(true);
  form_->addRow(register_info_);
  layout_->addWidget(make_nudge_box());
  auto* opacity = new QSlider(Qt::Horizontal, this);
  opacity->setRange(5, 100);
  opacity->setValue(45);
  connect(opacity, &QSlider::valueChanged, this,
          [this](int v) { host_.view().set_mirror_opacity(v / 100.0); });
  form_->addRow(tr("Mirror opacity"), opacity);
}

QWidget* MirrorPage::make_nudge_box() {
  auto* box = new QGroupBox(tr("Nudge the mirror"), this);
  auto* row = new QHBoxLayout(box);
  const std::pair<QString, Eigen::Vector3d> moves[] = {{"←", {-1, 0, 0}},     {"→", {1, 0, 0}},
                                                       {"front", {0, -1, 0}}, {"back", {0, 1, 0}},
                                                       {"↑", {0, 0, 1}},      {"↓", {0, 0, -1}}};
  for (const auto& [label, delta] : moves) {
    auto* b = new QPushButton(label, box);
    b->setToolTip(tr("Move the mirrored skull 1 mm"));
    connect(b, &QPushButton::clicked, this, [this, delta = delta] {
      host_.push(
          commands::move_mirrored(Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d::Zero(), delta),
          tr("Moving the mirror"));
    });
    row->addWidget(b);
  }
  return box;
}

void MirrorPage::show_state(const PlanState& s) {
  QString text;
  if (!s.registration)
    text = s.mirrored ? tr("Mirrored, not registered.") : tr("Not mirrored yet.");
  else if (s.registration->usable())
    text = tr("Registered: RMS %1 mm, %2 iterations — %3")
               .arg(s.registration->rms_mm, 0, 'f', 2)
               .arg(s.registration->iterations)
               .arg(QString::fromUtf8(registration_verdict(*s.registration)));
  else
    text = tr("Registration failed: %1").arg(QString::fromStdString(s.registration->message));
  register_info_->setText(text);
}

void MirrorPage::surface_clicked(const Eigen::Vector3d& p) {
  roi_center_ = p;
  roi_only_->setChecked(true);
  host_.show_message(tr("Registration region centred at the clicked point."), false);
}

}  // namespace cranioplan::gui
