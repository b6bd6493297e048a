#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QPushButton>
#include <QSlider>

#include "step_pages.h"

namespace cranioplan::gui {

ClipPage::ClipPage(PageHost& host) : StepPage(kClipStep, host) {
  clip_on_ = new QCheckBox(tr("Clip the skulls"), this);
  clip_on_->setObjectName("clipOn");
  clip_axis_ = new QComboBox(this);
  clip_axis_->addItems({tr("Left–right"), tr("Front–back"), tr("Up–down")});
  clip_position_ = new QSlider(Qt::Horizontal, this);
  clip_position_->setObjectName("clipPosition");
  clip_position_->setRange(-120, 120);
  // The plane is a command when it settles: a released slider, not every step of a drag.
  auto send = [this] { host_.push(clip_command()); };
  connect(clip_on_, &QCheckBox::toggled, this, send);
  connect(clip_axis_, &QComboBox::currentIndexChanged, this, [this, send] {
    if (clip_on_->isChecked()) send();
  });
  connect(clip_position_, &QSlider::sliderReleased, this, send);
  connect(clip_position_, &QSlider::valueChanged, this, [this, send] {
    if (!clip_position_->isSliderDown() && clip_on_->isChecked()) send();
  });
  form_->addRow(clip_on_);
  form_->addRow(tr("Cut across"), clip_axis_);
  form_->addRow(tr("Position"), clip_position_);
  // The CT's slices show the inner edge and what lies under the defect where the bone is.
  QPushButton* slices = add_button(tr("Show CT slices"), "showSlices");
  slices->setToolTip(
      tr("Axial, coronal and sagittal slices of the CT beside the 3D view "
         "(View → Layout); a click on the skull moves them there"));
  connect(slices, &QPushButton::clicked, this, [this] { host_.show_slices(); });
}

Command ClipPage::clip_command() const {
  if (!clip_on_->isChecked()) return commands::clear_clip_plane();
  const PlanState& s = host_.plan();
  const Eigen::Vector3d center = s.skull ? s.skull->centroid : Eigen::Vector3d::Zero();
  const Eigen::Vector3d n = Eigen::Vector3d::Unit(clip_axis_->currentIndex());
  return commands::set_clip_plane(Plane::through(center + clip_position_->value() * n, n));
}

void ClipPage::show_state(const PlanState& s) {
  const QSignalBlocker block(clip_on_);
  clip_on_->setChecked(s.clip_plane.has_value());
}

}  // namespace cranioplan::gui
