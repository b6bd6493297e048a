#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QVBoxLayout>
#include <cmath>

#include "step_pages.h"

namespace cranioplan::gui {

namespace {

// The landmark names of the list, in its order.
const char* const kLandmarkNames[] = {"nasion", "orbit_left", "orbit_right", "midline"};

// A slider beside a field, in half-unit steps over ±20.
QSlider* linked_slider(QDoubleSpinBox* field, QWidget* parent) {
  auto* slider = new QSlider(Qt::Horizontal, parent);
  slider->setRange(-40, 40);
  QObject::connect(slider, &QSlider::valueChanged, field,
                   [field](int v) { field->setValue(0.5 * v); });
  QObject::connect(field, &QDoubleSpinBox::valueChanged, slider, [slider](double v) {
    const QSignalBlocker block(slider);
    slider->setValue(static_cast<int>(std::lround(2.0 * v)));
  });
  return slider;
}

}  // namespace

PlanePage::PlanePage(PageHost& host) : StepPage(kPlaneStep, host) {
  landmark_ = new QComboBox(this);
  landmark_->setObjectName("landmark");
  landmark_->addItems(
      {tr("Nasion"), tr("Left orbit centre"), tr("Right orbit centre"), tr("Midline point")});
  form_->addRow(tr("Click places"), landmark_);
  QPushButton* clear = add_button(tr("Clear landmarks"), "clearLandmarks");
  connect(clear, &QPushButton::clicked, this, [this] {
    for (const char* name : kLandmarkNames) host_.push(commands::clear_landmark(name));
  });
  QPushButton* fit = add_button(tr("Fit plane"), "fitPlane");
  fit->setToolTip(tr("Landmarks (if all three are set) or automatic, refined by symmetry"));
  connect(fit, &QPushButton::clicked, this,
          [this] { host_.push(commands::fit_plane(), tr("Fitting the plane")); });
  plane_info_ = new QLabel(this);
  plane_info_->setWordWrap(true);
  form_->addRow(plane_info_);
  layout_->addWidget(make_adjust_box());
}

QWidget* PlanePage::make_adjust_box() {
  auto* box = new QGroupBox(tr("Adjust by hand"), this);
  auto* bl = new QFormLayout(box);
  adjust_axis_ = new QComboBox(box);
  adjust_axis_->addItems({tr("Up–down axis"), tr("Front–back axis")});
  adjust_angle_ = new QDoubleSpinBox(box);
  adjust_angle_->setRange(-20, 20);
  adjust_angle_->setSingleStep(0.5);
  adjust_angle_->setSuffix("°");
  adjust_shift_ = new QDoubleSpinBox(box);
  adjust_shift_->setRange(-20, 20);
  adjust_shift_->setSingleStep(0.5);
  adjust_shift_->setSuffix(" mm");
  auto* apply = new QPushButton(tr("Apply"), box);
  apply->setObjectName("adjustPlane");
  connect(apply, &QPushButton::clicked, this, [this] {
    const Eigen::Vector3d axis =
        adjust_axis_->currentIndex() == 0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    host_.push(commands::adjust_plane(axis, adjust_angle_->value(), adjust_shift_->value()),
               tr("Moving the plane"));
  });
  bl->addRow(tr("Turn about"), adjust_axis_);
  bl->addRow(tr("Angle"), adjust_angle_);
  bl->addRow(QString(), linked_slider(adjust_angle_, box));
  bl->addRow(tr("Shift"), adjust_shift_);
  bl->addRow(QString(), linked_slider(adjust_shift_, box));
  bl->addRow(apply);
  return box;
}

void PlanePage::show_state(const PlanState& s) {
  QString fit;
  if (s.plane_fit)
    fit = tr("Fit: %1").arg(QString::fromStdString(describe_plane_fit(*s.plane_fit)));
  const int n = (s.landmarks.nasion ? 1 : 0) + (s.landmarks.orbit_left ? 1 : 0) +
                (s.landmarks.orbit_right ? 1 : 0);
  plane_info_->setText(
      tr("Landmarks: %1 of 3 set, %2 midline points.").arg(n).arg(s.landmarks.midline.size()) +
      (fit.isEmpty() ? QString() : "<br>" + fit));
}

void PlanePage::surface_clicked(const Eigen::Vector3d& p) {
  // A click places the chosen landmark; the list moves on to the next of the three.
  const int index = landmark_->currentIndex();
  host_.push(commands::set_landmark(kLandmarkNames[index], p));
  // On to the next of the three; after the third, midline points (a further click adds one
  // rather than moving the right orbit's).
  if (index < 3) landmark_->setCurrentIndex(index + 1);
}

}  // namespace cranioplan::gui
