#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSpinBox>
#include <algorithm>
#include <cmath>

#include "cranioplan/algorithms/planning/autoplan.h"
#include "declared_fields.h"
#include "step_pages.h"

namespace cranioplan::gui {

namespace {
// The manual path's defaults are the automatic plan's: fitted to the bone, so that the implant
// meets the cut face all around and the quality check passes.
const ImplantParams& automatic_implant() {
  static const ImplantParams p = AutoplanParams{}.implant;
  return p;
}

}  // namespace

BuildPage::BuildPage(PageHost& host) : StepPage(kBuildStep, host) {
  add_build_and_result();
  add_shell_controls();
  add_material_controls();
  add_zone_controls();
  show_material(0);
  add_perforation_controls();
  add_tab_controls();
  watch_controls();
}

void BuildPage::add_build_and_result() {
  // The step's action first, with what became of it, so it is in sight whatever the options.
  build_ = add_button(tr("Build implant"), "build");
  connect(build_, &QPushButton::clicked, this,
          [this] { host_.push(commands::build_implant(params()), tr("Building the implant")); });
  info_ = new QLabel(this);
  info_->setObjectName("buildInfo");
  info_->setWordWrap(true);
  form_->addRow(info_);
  changed_ =
      new QLabel(tr("<b>Changed since the last build:</b> press Build implant to apply."), this);
  changed_->setObjectName("buildChanged");
  changed_->setWordWrap(true);
  changed_->setStyleSheet("QLabel{color:#8a5a00}");
  changed_->hide();
  form_->addRow(changed_);
  verdict_ = new QLabel(this);
  verdict_->setObjectName("buildVerdict");
  verdict_->setWordWrap(true);
  verdict_->setTextFormat(Qt::RichText);
  verdict_->hide();
  form_->addRow(verdict_);
}

void BuildPage::add_shell_controls() {
  method_ = new QComboBox(this);
  method_->setObjectName("implantMethod");
  method_->addItems({tr("Shell (fitted surfaces)"), tr("Delaunay 3D (Egger et al. 2017)")});
  resolution_ = declared_spin(this, "implantResolution", spec_of<ImplantParams>("resolution_mm"),
                              automatic_implant().resolution_mm, 0.1);
  // Left unset (its lowest value, 0) the thickness is the bone's around the rim.
  thickness_ =
      declared_spin(this, "implantThickness", spec_of<ImplantParams>("thickness_mm"), 0.0, 0.1);
  allow_unset(thickness_, tr("measured at the rim"));
  fit_ = declared_spin(this, "implantFit", spec_of<ImplantParams>("fit_to_bone_mm"),
                       automatic_implant().fit_to_bone_mm, 0.5);
  fit_->setSpecialValueText(tr("off"));
  form_->addRow(tr("Method"), method_);
  form_->addRow(tr("Resolution"), resolution_);
  form_->addRow(tr("Thickness without inner markers"), thickness_);
  form_->addRow(tr("Fit to the bone"), fit_);
  fit_note_ = new QLabel(this);
  fit_note_->setObjectName("fitNote");
  fit_note_->setWordWrap(true);
  fit_note_->hide();
  form_->addRow(fit_note_);
}

void BuildPage::add_material_controls() {
  // The material: a preset fills its values, which may then be changed.
  material_ = new QComboBox(this);
  material_->setObjectName("implantMaterial");
  material_->addItem(tr("None (the plan's surfaces)"));
  for (const Material& m : material_presets()) material_->addItem(QString::fromStdString(m.name));
  material_->addItem(tr("Custom"));
  const Material custom;
  clearance_ = declared_spin(this, "materialClearance", spec_of<Material>("edge_clearance_mm"),
                             custom.edge_clearance_mm, 0.1);
  under_contour_ =
      declared_spin(this, "materialUnderContour", spec_of<Material>("under_contour_mm"),
                    custom.under_contour_mm, 0.1);
  min_thickness_ =
      declared_spin(this, "materialMinThickness", spec_of<Material>("min_thickness_mm"),
                    custom.min_thickness_mm, 0.1);
  // Left unset (its lowest value, 0) the implant follows the bone.
  plate_ = declared_spin(this, "materialPlate", spec_of<Material>("thickness_mm"), 0.0, 0.1);
  allow_unset(plate_, tr("follows the bone"));
  density_ = declared_spin(this, "materialDensity", spec_of<Material>("density_g_cm3"),
                           custom.density_g_cm3, 0.01);
  form_->addRow(tr("Material"), material_);
  form_->addRow(tr("Edge clearance"), clearance_);
  form_->addRow(tr("Under-contour"), under_contour_);
  form_->addRow(tr("Minimum thickness"), min_thickness_);
  form_->addRow(tr("Plate thickness"), plate_);
  form_->addRow(tr("Density"), density_);
  connect(material_, &QComboBox::currentIndexChanged, this, [this](int i) {
    show_material(i);
    // Clearance and under-contour are made by the fit to the bone.
    if (i > 0 && fit_->value() == 0) fit_->setValue(4.0);
  });
}

void BuildPage::add_zone_controls() {
  // Clearance zones: a wider gap along stretches of the rim the user marks.
  mark_zone_ = make_button(tr("Mark a wider clearance on the rim"), "markZone");
  mark_zone_->setCheckable(true);
  mark_zone_->setToolTip(
      tr("Then click the rim: the stretch within the radius keeps the zone's "
         "clearance (e.g. 3 mm under the temporalis muscle)"));
  const ClearanceZone zone;
  zone_radius_ =
      declared_spin(this, "zoneRadius", spec_of<ClearanceZone>("radius_mm"), zone.radius_mm, 1);
  zone_clearance_ = declared_spin(this, "zoneClearance", spec_of<ClearanceZone>("clearance_mm"),
                                  zone.clearance_mm, 0.1);
  remove_zone_ = make_button(tr("Remove the last zone"), "removeZone");
  connect(remove_zone_, &QPushButton::clicked, this, [this] {
    if (zones_.empty()) return;
    zones_.pop_back();
    rebuild();
  });
  form_->addRow(mark_zone_);
  form_->addRow(tr("Zone radius"), zone_radius_);
  form_->addRow(tr("Zone clearance"), zone_clearance_);
  form_->addRow(remove_zone_);
}

void BuildPage::add_perforation_controls() {
  // Perforations: a pattern, and single holes added or taken away by clicks on the implant.
  perforate_ = new QCheckBox(tr("Perforations on a pattern"), this);
  perforate_->setObjectName("perforate");
  perforate_->setToolTip(tr("Holes through the implant for drainage and dura suspension"));
  const PerforationParams holes;
  hole_diameter_ = declared_spin(this, "holeDiameter", spec_of<PerforationParams>("diameter_mm"),
                                 holes.diameter_mm, 0.5);
  hole_spacing_ = declared_spin(this, "holeSpacing", spec_of<PerforationParams>("spacing_mm"),
                                holes.spacing_mm, 1);
  hole_edge_ = declared_spin(this, "holeEdge", spec_of<PerforationParams>("edge_distance_mm"),
                             holes.edge_distance_mm, 0.5);
  add_hole_ = make_button(tr("Add a hole"), "addHole");
  remove_hole_ = make_button(tr("Remove a hole"), "removeHole");
  for (QPushButton* b : {add_hole_, remove_hole_}) {
    b->setCheckable(true);
    b->setToolTip(tr("Then click the implant"));
  }
  form_->addRow(perforate_);
  form_->addRow(tr("Hole diameter"), hole_diameter_);
  form_->addRow(tr("Hole spacing"), hole_spacing_);
  form_->addRow(tr("Distance from the edge"), hole_edge_);
  auto* hole_buttons = new QHBoxLayout;
  hole_buttons->addWidget(add_hole_);
  hole_buttons->addWidget(remove_hole_);
  form_->addRow(hole_buttons);
}

void BuildPage::add_tab_controls() {
  // Fixation tabs: evenly placed, or where the user clicks on the bone beyond the edge.
  tabs_ = new QCheckBox(tr("Fixation tabs along the rim"), this);
  tabs_->setObjectName("tabs");
  tabs_->setToolTip(
      tr("Tabs onto the outer table with a countersunk screw hole each, away from thin bone "
         "and from the midline"));
  const TabParams tabs;
  tab_count_ = declared_count(this, "tabCount", spec_of<TabParams>("count"), tabs.count);
  tab_count_->setSpecialValueText(tr("one per 40 mm of rim"));
  tab_screws_ = declared_count(this, "tabScrews", spec_of<TabParams>("screws"), tabs.screws);
  tab_length_ =
      declared_spin(this, "tabLength", spec_of<TabParams>("length_mm"), tabs.length_mm, 0.5);
  add_tab_ = make_button(tr("Add a tab"), "addTab");
  remove_tab_ = make_button(tr("Remove a tab"), "removeTab");
  add_tab_->setToolTip(tr("Then click the bone beyond the implant's edge"));
  remove_tab_->setToolTip(tr("Then click the tab"));
  for (QPushButton* b : {add_tab_, remove_tab_}) b->setCheckable(true);
  for (QPushButton* b : {mark_zone_, add_hole_, remove_hole_, add_tab_, remove_tab_})
    connect(b, &QPushButton::toggled, this, [this, b](bool on) {
      if (on) click_mode(b);
      host_.view().set_pick_target(pick_target());
    });
  form_->addRow(tabs_);
  form_->addRow(tr("Tabs"), tab_count_);
  form_->addRow(tr("Screws per tab"), tab_screws_);
  form_->addRow(tr("Tab length"), tab_length_);
  auto* tab_buttons = new QHBoxLayout;
  for (QPushButton* b : {add_tab_, remove_tab_}) tab_buttons->addWidget(b);
  form_->addRow(tab_buttons);
  auto* drag_hint = new QLabel(tr("Drag a tab (along the rim) or a hole (over the implant) by "
                                  "its blue ball to move it."),
                               this);
  drag_hint->setWordWrap(true);
  form_->addRow(drag_hint);
}

void BuildPage::watch_controls() {
  // Any control changed after a build: the implant shown is not what the controls say.
  for (auto* b : findChildren<QDoubleSpinBox*>())
    connect(b, &QDoubleSpinBox::valueChanged, this, &BuildPage::mark_changed);
  for (auto* b : findChildren<QSpinBox*>())
    connect(b, &QSpinBox::valueChanged, this, &BuildPage::mark_changed);
  for (auto* b : findChildren<QComboBox*>())
    connect(b, &QComboBox::currentIndexChanged, this, &BuildPage::mark_changed);
  for (auto* b : findChildren<QCheckBox*>())
    connect(b, &QCheckBox::toggled, this, &BuildPage::mark_changed);
}

void BuildPage::mark_changed() {
  if (showing_ || !host_.plan().implant) return;
  changed_->show();
  verdict_->setEnabled(false);  // greyed: of the implant before the change
  QFont f = build_->font();
  f.setBold(true);
  build_->setFont(f);
}

void BuildPage::show_verdict(const QString& html) {
  set_wrapped_text(verdict_, html);
  verdict_->setVisible(!html.isEmpty() && host_.plan().implant);
}

void BuildPage::show_material(int index) {
  const auto& presets = material_presets();
  const bool none = index <= 0;
  for (QDoubleSpinBox* b : {clearance_, under_contour_, min_thickness_, plate_, density_})
    b->setEnabled(!none);
  if (none || index > static_cast<int>(presets.size())) return;  // none, or custom: as they are
  const Material& m = presets[static_cast<size_t>(index - 1)];
  clearance_->setValue(m.edge_clearance_mm);
  under_contour_->setValue(m.under_contour_mm);
  min_thickness_->setValue(m.min_thickness_mm);
  plate_->setValue(std::isnan(m.thickness_mm) ? 0.0 : m.thickness_mm);
  density_->setValue(m.density_g_cm3);
}

void BuildPage::rebuild() {
  if (!host_.plan().implant_params) return;
  host_.push(commands::build_implant(params()), tr("Building the implant"));
}

void BuildPage::click_mode(QPushButton* on) {
  for (QPushButton* b : {mark_zone_, add_hole_, remove_hole_, add_tab_, remove_tab_})
    if (b != on && b->isChecked()) {
      const QSignalBlocker block(b);
      b->setChecked(false);
    }
}

SkullView::PickTarget BuildPage::pick_target() const {
  if (mark_zone_->isChecked() || add_tab_->isChecked() || remove_tab_->isChecked())
    return SkullView::PickTarget::Original;
  if (add_hole_->isChecked() || remove_hole_->isChecked()) return SkullView::PickTarget::Implant;
  return SkullView::PickTarget::None;
}

void BuildPage::take_tabs_over() {
  const PlanState& s = host_.plan();
  if (!tab_positions_.empty() || !s.implant) return;
  for (const Tab& t : s.implant->result().tabs) tab_positions_.push_back(t.rim);
}

namespace {
// The tab of `tabs` whose middle lies nearest `point`, within 10 mm; none otherwise.
std::optional<size_t> tab_near(const std::vector<Tab>& tabs, const Eigen::Vector3d& point) {
  std::optional<size_t> best;
  double best_mm = 10.0;
  for (size_t k = 0; k < tabs.size(); ++k) {
    const double mm = (tabs[k].rim + 0.5 * tabs[k].length_mm * tabs[k].outward - point).norm();
    if (mm < best_mm) best_mm = mm, best = k;
  }
  return best;
}
}  // namespace

void BuildPage::surface_clicked(const Eigen::Vector3d& point) {
  if (add_tab_->isChecked() || remove_tab_->isChecked()) {
    const PlanState& s = host_.plan();
    const std::vector<Tab> shown = s.implant ? s.implant->result().tabs : std::vector<Tab>{};
    if (add_tab_->isChecked()) {
      if (tabs_->isChecked()) take_tabs_over();
      tab_positions_.push_back(point);
      tabs_->setChecked(true);
      rebuild();
      return;
    }
    const std::optional<size_t> k = tab_near(shown, point);
    if (!k) {
      host_.show_message(tr("No tab within 10 mm of the click."), true);
      return;
    }
    take_tabs_over();
    if (*k < tab_positions_.size()) tab_positions_.erase(tab_positions_.begin() + *k);
    if (tab_positions_.empty()) tabs_->setChecked(false);  // the last one gone: none
    rebuild();
    return;
  }
  if (add_hole_->isChecked()) {
    added_holes_.push_back(point);
    rebuild();
    return;
  }
  if (remove_hole_->isChecked()) {
    // The nearest hole of the implant shown: one the user added goes from that list, one of
    // the pattern's is left out from now on.
    const PlanState& s = host_.plan();
    if (!s.implant || s.implant->result().holes.empty()) return;
    const Hole* nearest = nullptr;
    for (const Hole& h : s.implant->result().holes)
      if (!nearest || (h.center - point).norm() < (nearest->center - point).norm()) nearest = &h;
    if ((nearest->center - point).norm() > 5.0) {
      host_.show_message(tr("No hole within 5 mm of the click."), true);
      return;
    }
    if (nearest->added) {
      auto closest =
          std::min_element(added_holes_.begin(), added_holes_.end(),
                           [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                             return (a - nearest->center).norm() < (b - nearest->center).norm();
                           });
      if (closest != added_holes_.end()) added_holes_.erase(closest);
    } else {
      removed_holes_.push_back(nearest->center);
    }
    rebuild();
    return;
  }
  if (!mark_zone_->isChecked()) return;
  zones_.push_back({point, zone_radius_->value(), zone_clearance_->value()});
  if (!host_.plan().implant_params) {
    host_.show_message(tr("Zone marked: it applies when the implant is built (fit to the bone)."),
                       false);
    return;
  }
  rebuild();
}

namespace {
// Handles' ids: holes from 1, tabs from kTabHandle (indices into the implant's lists).
constexpr int kTabHandle = 10000;
}  // namespace

Eigen::Vector3d BuildPage::tab_handle(const Tab& t) {
  return t.rim + (t.length_mm + 1.5) * t.outward + 1.3 * t.normal;
}

std::vector<SkullView::Handle> BuildPage::handles(const PlanState& s) const {
  std::vector<SkullView::Handle> out;
  if (!s.implant) return out;
  const ImplantResult& r = s.implant->result();
  for (size_t k = 0; k < r.holes.size(); ++k)
    out.push_back({static_cast<int>(k) + 1, r.holes[k].center, SkullView::PickTarget::Implant});
  // A tab's ball on the bone just beyond its tip (where no part of the tab hides it); it is
  // dragged over the bone.
  for (size_t k = 0; k < r.tabs.size(); ++k)
    out.push_back(
        {kTabHandle + static_cast<int>(k), tab_handle(r.tabs[k]), SkullView::PickTarget::Original});
  return out;
}

void BuildPage::handle_dropped(int id, const Eigen::Vector3d& point) {
  const PlanState& s = host_.plan();
  if (!s.implant) return;
  const ImplantResult& r = s.implant->result();
  if (id >= kTabHandle) {
    // The tab goes to the rim nearest where it was let go.
    const auto k = static_cast<size_t>(id - kTabHandle);
    if (k >= r.tabs.size()) return;
    take_tabs_over();
    if (k < tab_positions_.size()) tab_positions_[k] = point;
    rebuild();
    return;
  }
  const auto k = static_cast<size_t>(id - 1);
  if (id < 1 || k >= r.holes.size()) return;
  const Hole& moved = r.holes[k];
  if (moved.added) {
    // One of the user's: the nearest of the page's list goes to the new place.
    auto closest = std::min_element(added_holes_.begin(), added_holes_.end(),
                                    [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                                      return (a - moved.center).norm() < (b - moved.center).norm();
                                    });
    if (closest == added_holes_.end()) return;
    *closest = point;
  } else {
    // The pattern's: left out there, added here.
    removed_holes_.push_back(moved.center);
    added_holes_.push_back(point);
  }
  rebuild();
}

ImplantParams BuildPage::params() const {
  ImplantParams p;
  p.method = method_->currentIndex() == 0 ? ImplantMethod::Shell : ImplantMethod::Delaunay3D;
  p.resolution_mm = resolution_->value();
  if (thickness_->value() > 0) p.thickness_mm = thickness_->value();
  p.surface_smoothing = automatic_implant().surface_smoothing;
  p.fit_to_bone_mm = fit_->value();
  const int index = material_->currentIndex();
  if (index > 0) {
    const auto& presets = material_presets();
    Material m;  // custom
    if (index <= static_cast<int>(presets.size())) m = presets[static_cast<size_t>(index - 1)];
    m.edge_clearance_mm = clearance_->value();
    m.under_contour_mm = under_contour_->value();
    m.min_thickness_mm = min_thickness_->value();
    m.thickness_mm = plate_->value() > 0 ? plate_->value() : std::nan("");
    m.density_g_cm3 = density_->value();
    p.material = m;
  }
  p.clearance_zones = zones_;
  p.perforations.pattern = perforate_->isChecked();
  p.perforations.diameter_mm = hole_diameter_->value();
  p.perforations.spacing_mm = hole_spacing_->value();
  p.perforations.edge_distance_mm = hole_edge_->value();
  p.perforations.added = added_holes_;
  p.perforations.removed = removed_holes_;
  if (tabs_->isChecked()) {
    p.tabs.automatic = tab_positions_.empty();
    p.tabs.positions = tab_positions_;
  }
  p.tabs.count = tab_count_->value();
  p.tabs.screws = tab_screws_->value();
  p.tabs.length_mm = tab_length_->value();
  if (p.tabs.any()) p.tabs.midline = host_.plan().plane;
  return p;
}

void BuildPage::show_state(const PlanState& s) {
  showing_ = true;
  if (s.implant.get() != shown_implant_) {  // a new implant (or none): what it was built with
    shown_implant_ = s.implant.get();
    changed_->hide();
    verdict_->setEnabled(true);
    QFont f = build_->font();
    f.setBold(false);
    build_->setFont(f);
    if (!s.implant) verdict_->hide();
  }
  // The controls show the parameters the plan's implant was built with (an automatic plan is
  // fitted to the bone), so pressing Build again keeps them unless changed.
  if (s.implant_params) {
    const ImplantParams& p = *s.implant_params;
    const QSignalBlocker b1(method_), b2(resolution_), b3(thickness_), b4(fit_), b5(material_);
    method_->setCurrentIndex(p.method == ImplantMethod::Shell ? 0 : 1);
    resolution_->setValue(p.resolution_mm);
    thickness_->setValue(std::isnan(p.thickness_mm) ? 0.0 : p.thickness_mm);
    fit_->setValue(p.fit_to_bone_mm);
    int index = 0;
    if (p.material) {
      const auto& presets = material_presets();
      index = static_cast<int>(presets.size()) + 1;  // custom
      for (size_t k = 0; k < presets.size(); ++k)
        if (presets[k].id == p.material->id) index = static_cast<int>(k) + 1;
    }
    material_->setCurrentIndex(index);
    for (QDoubleSpinBox* b : {clearance_, under_contour_, min_thickness_, plate_, density_})
      b->setEnabled(p.material.has_value());
    if (p.material) {
      clearance_->setValue(p.material->edge_clearance_mm);
      under_contour_->setValue(p.material->under_contour_mm);
      min_thickness_->setValue(p.material->min_thickness_mm);
      plate_->setValue(std::isnan(p.material->thickness_mm) ? 0.0 : p.material->thickness_mm);
      density_->setValue(p.material->density_g_cm3);
    }
    zones_ = p.clearance_zones;
    const QSignalBlocker b6(perforate_);
    perforate_->setChecked(p.perforations.pattern);
    hole_diameter_->setValue(p.perforations.diameter_mm);
    hole_spacing_->setValue(p.perforations.spacing_mm);
    hole_edge_->setValue(p.perforations.edge_distance_mm);
    added_holes_ = p.perforations.added;
    removed_holes_ = p.perforations.removed;
    const QSignalBlocker b7(tabs_);
    tabs_->setChecked(p.tabs.any());
    tab_count_->setValue(p.tabs.count);
    tab_screws_->setValue(p.tabs.screws);
    tab_length_->setValue(p.tabs.length_mm);
    tab_positions_ = p.tabs.positions;
  }
  remove_zone_->setEnabled(!zones_.empty());
  // The margin field shows the one asked; under it, which one the build used and why.
  const bool other_margin = s.implant && !s.implant->result().fit_margin_note.empty();
  if (other_margin) {
    QString note = QString::fromStdString(s.implant->result().fit_margin_note);
    note[0] = note[0].toUpper();
    fit_note_->setText(note + ".");
  }
  fit_note_->setVisible(other_margin);
  QString text =
      s.implant ? tr("Implant: %1 triangles, %2")
                      .arg(s.implant->result().mesh.n_faces())
                      .arg(s.implant->result().watertight ? tr("watertight") : tr("not watertight"))
                : tr("No implant yet.");
  if (s.implant_params && s.implant_params->material)
    text += "<br>" + QString::fromStdString(describe(*s.implant_params->material));
  if (s.implant && !s.implant->result().holes.empty())
    text += "<br>" + (s.implant->result().holes.size() == 1 ? tr("%1 hole of %2 mm.")
                                                            : tr("%1 holes of %2 mm."))
                         .arg(s.implant->result().holes.size())
                         .arg(hole_diameter_->value(), 0, 'f', 1);
  if (s.implant && !s.implant->result().tabs.empty())
    text += "<br>" + (s.implant->result().tabs.size() == 1 ? tr("%1 fixation tab.")
                                                           : tr("%1 fixation tabs."))
                         .arg(s.implant->result().tabs.size());
  if (!zones_.empty())
    text += "<br>" + (zones_.size() == 1
                          ? tr("1 clearance zone on the rim (orange).")
                          : tr("%1 clearance zones on the rim (orange).").arg(zones_.size()));
  info_->setText(text);
  showing_ = false;
}

}  // namespace cranioplan::gui
