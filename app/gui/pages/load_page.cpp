#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/io/load_skull.h"
#include "step_pages.h"

namespace cranioplan::gui {

namespace {
constexpr double kAutomatic = -1001.0;  // the threshold field's "automatic"
}  // namespace

LoadPage::LoadPage(PageHost& host) : StepPage(kLoadStep, host) {
  QPushButton* open = add_button(tr("Open mesh or CT…"), "pageOpen");
  connect(open, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open a skull"), QString(),
        tr("Skull (*.stl *.ply *.obj *.off *.vtk *.vtp *.inv3 *.nrrd *.nhdr *.nii *.nii.gz);;All "
           "(*)"));
    if (!path.isEmpty()) host_.open_skull(path);
  });
  QPushButton* sample = add_button(tr("Open the sample case"), "pageSample");
  connect(sample, &QPushButton::clicked, this, [this] { host_.open_sample(); });
  units_ = new QComboBox(this);
  units_->setObjectName("meshUnits");
  for (const LengthUnit& u : length_units())
    units_->addItem(QStringLiteral("%1 (%2)").arg(tr(u.label), QString::fromLatin1(u.name)), u.mm);
  units_->setToolTip(
      tr("The length unit a mesh file was written in (STL, PLY, OBJ and OFF carry none). A "
         "skull of the wrong size is refused, naming the unit it looks to be in."));
  threshold_ = new QDoubleSpinBox(this);
  threshold_->setObjectName("threshold");
  // Automatic by default: 300 HU for a CT, 0.5 for a mask (a segmentation), so that either
  // opens with the default; a value typed here is used as it is.
  threshold_->setRange(kAutomatic, 3000);
  threshold_->setValue(kAutomatic);
  threshold_->setSpecialValueText(tr("automatic (CT 300 HU, mask 0.5)"));
  threshold_->setSuffix(" HU");
  threshold_->setToolTip(
      tr("The iso-value of the bone surface: automatic is 300 HU for a CT and 0.5 for a mask"));
  form_->addRow(tr("Mesh units"), units_);
  form_->addRow(tr("CT bone threshold"), threshold_);
  skull_info_ = new QLabel(this);
  skull_info_->setWordWrap(true);
  form_->addRow(skull_info_);
}

double LoadPage::mesh_unit_mm() const { return units_->currentData().toDouble(); }

bool LoadPage::set_mesh_unit(const std::string& name) {
  const std::optional<LengthUnit> unit = length_unit_named(name);
  if (!unit) return false;
  units_->setCurrentIndex(units_->findData(unit->mm));
  return true;
}

double LoadPage::threshold() const {
  return threshold_->value() <= kAutomatic ? std::numeric_limits<double>::quiet_NaN()
                                           : threshold_->value();
}

void LoadPage::set_threshold(double hu) { threshold_->setValue(std::isnan(hu) ? kAutomatic : hu); }

void LoadPage::show_state(const PlanState& s) {
  QString info = tr("No skull loaded.");
  if (s.skull) {
    const LoadedSkull& loaded = s.skull->surface->loaded;
    info = tr("%1<br>%2 triangles")
               .arg(QString::fromStdString(loaded.description).toHtmlEscaped())
               .arg(s.skull->surface->mesh.n_faces());
    // What the reader changed or found (a skull turned outward, non-manifold edges).
    for (const std::string& w : loaded.warnings)
      info += QStringLiteral("<br><span style='color:#a05a00'>⚠ %1</span>")
                  .arg(QString::fromStdString(w).toHtmlEscaped());
    // What it has that needs no repair (a flat cap where the scan ended).
    for (const std::string& n : loaded.notes)
      info += QStringLiteral("<br>ℹ %1").arg(QString::fromStdString(n).toHtmlEscaped());
  }
  skull_info_->setText(info);
}

}  // namespace cranioplan::gui
