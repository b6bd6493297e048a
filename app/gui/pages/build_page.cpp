#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <cmath>

#include "step_pages.h"

namespace cranioplan::gui {

BuildPage::BuildPage(PageHost& host) : StepPage(7, host) {
  method_ = new QComboBox(this);
  method_->setObjectName("implantMethod");
  method_->addItems({tr("Shell (fitted surfaces)"), tr("Delaunay 3D (the paper's)")});
  resolution_ = new QDoubleSpinBox(this);
  resolution_->setRange(0.3, 5);
  resolution_->setValue(1.0);
  resolution_->setSingleStep(0.1);
  resolution_->setSuffix(" mm");
  thickness_ = new QDoubleSpinBox(this);
  thickness_->setRange(0, 15);
  thickness_->setValue(0);
  thickness_->setSpecialValueText(tr("measured at the rim"));
  thickness_->setSuffix(" mm");
  fit_ = new QDoubleSpinBox(this);
  fit_->setObjectName("implantFit");
  fit_->setRange(0, 8);
  fit_->setSingleStep(0.5);
  fit_->setSpecialValueText(tr("off"));
  fit_->setSuffix(" mm");
  fit_->setToolTip(
      tr("Build the shell this far over the bone and subtract the skull: the implant meets "
         "the cut face all around and never enters the bone (about 1 s per rebuild)"));
  form_->addRow(tr("Method"), method_);
  form_->addRow(tr("Resolution"), resolution_);
  form_->addRow(tr("Thickness without inner markers"), thickness_);
  form_->addRow(tr("Fit to the bone"), fit_);
  QPushButton* build = add_button(tr("Build implant"), "build");
  connect(build, &QPushButton::clicked, this,
          [this] { host_.push(commands::build_implant(params()), tr("Building the implant")); });
  info_ = new QLabel(this);
  info_->setWordWrap(true);
  form_->addRow(info_);
}

ImplantParams BuildPage::params() const {
  ImplantParams p;
  p.method = method_->currentIndex() == 0 ? ImplantMethod::Shell : ImplantMethod::Delaunay3D;
  p.resolution_mm = resolution_->value();
  if (thickness_->value() > 0) p.thickness_mm = thickness_->value();
  p.surface_smoothing = 0.003;
  p.fit_to_bone_mm = fit_->value();
  return p;
}

void BuildPage::show_state(const PlanState& s) {
  // The controls show the parameters the plan's implant was built with (an automatic plan is
  // fitted to the bone), so pressing Build again keeps them unless changed.
  if (s.implant_params) {
    const ImplantParams& p = *s.implant_params;
    const QSignalBlocker b1(method_), b2(resolution_), b3(thickness_), b4(fit_);
    method_->setCurrentIndex(p.method == ImplantMethod::Shell ? 0 : 1);
    resolution_->setValue(p.resolution_mm);
    thickness_->setValue(std::isnan(p.thickness_mm) ? 0.0 : p.thickness_mm);
    fit_->setValue(p.fit_to_bone_mm);
  }
  info_->setText(
      s.implant ? tr("Implant: %1 triangles, %2")
                      .arg(s.implant->result().mesh.n_faces())
                      .arg(s.implant->result().watertight ? tr("watertight") : tr("not watertight"))
                : tr("No implant yet."));
}

}  // namespace cranioplan::gui
