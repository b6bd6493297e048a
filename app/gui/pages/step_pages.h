#pragma once
// The nine wizard pages. Each is built with its host and shows the state it is given; the
// factory make_step_page (step_page.h) makes them in step order.
#include <optional>

#include "step_page.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QSlider;
class QSpinBox;
class QTextBrowser;

namespace cranioplan::gui {

/// Step 1: open a mesh or a CT, its length unit and the bone threshold.
class LoadPage : public StepPage {
 public:
  explicit LoadPage(PageHost& host);
  void show_state(const PlanState& state) override;
  /// Millimetres per unit of the mesh files read next.
  double mesh_unit_mm() const;
  /// Chooses the unit by name (mm, cm, m, in, um); false for another name.
  bool set_mesh_unit(const std::string& name);
  /// The CT bone threshold of step 1's field; NaN: automatic (300 HU for a CT, 0.5 for a
  /// mask), the default.
  double threshold() const;
  void set_threshold(double hu);

 private:
  QDoubleSpinBox* threshold_;
  QComboBox* units_;
  QLabel* skull_info_;
};

/// Step 2: landmarks by clicks, the plane's fit, and turning or shifting it by hand.
class PlanePage : public StepPage {
 public:
  explicit PlanePage(PageHost& host);
  void show_state(const PlanState& state) override;
  void surface_clicked(const Eigen::Vector3d& point) override;
  SkullView::PickTarget pick_target() const override { return SkullView::PickTarget::Original; }

 private:
  QWidget* make_adjust_box();

  QComboBox* landmark_;
  QLabel* plane_info_;
  QComboBox* adjust_axis_ = nullptr;
  QDoubleSpinBox* adjust_angle_ = nullptr;
  QDoubleSpinBox* adjust_shift_ = nullptr;
};

/// Step 3: mirror, register (whole skull or a region around a clicked point), nudge.
class MirrorPage : public StepPage {
 public:
  explicit MirrorPage(PageHost& host);
  void show_state(const PlanState& state) override;
  void surface_clicked(const Eigen::Vector3d& point) override;
  SkullView::PickTarget pick_target() const override { return SkullView::PickTarget::Original; }

 private:
  QWidget* make_nudge_box();

  QCheckBox* roi_only_;
  QDoubleSpinBox* roi_radius_;
  QLabel* register_info_;
  std::optional<Eigen::Vector3d> roi_center_;
};

/// Step 4: a clip plane across one of the three axes.
class ClipPage : public StepPage {
 public:
  explicit ClipPage(PageHost& host);
  void show_state(const PlanState& state) override;

 private:
  Command clip_command() const;

  QCheckBox* clip_on_;
  QComboBox* clip_axis_;
  QSlider* clip_position_;
};

/// Steps 5 and 6: buttons for the step's two marker types, clicks place them, drags move them.
class MarkersPage : public StepPage {
 public:
  MarkersPage(int step, PageHost& host, MarkerType first, MarkerType second);
  void show_state(const PlanState& state) override;
  void surface_clicked(const Eigen::Vector3d& point) override;
  SkullView::PickTarget pick_target() const override;
  bool markers_editable() const override { return true; }

 protected:
  QString keys_hint() const override;
  /// The row that counts the markers of the two types (each page puts it where it reads best).
  void add_counts_row();

 private:
  MarkerType first_, second_;
  QLabel* counts_ = nullptr;
};

/// Step 5: edge markers, proposed automatically or imported.
class EdgeMarkersPage : public MarkersPage {
 public:
  explicit EdgeMarkersPage(PageHost& host);
  void show_state(const PlanState& state) override;

 private:
  void import_markers();
  /// The shape model's row: a box to guide the proposal with it and the file chosen, both
  /// remembered in the settings ("shapeModel/use", "shapeModel/path").
  void add_shape_model_row();
  void choose_shape_model();
  /// The model file the next proposal uses: empty unless the box is ticked and a file chosen.
  std::string shape_model_path() const;
  /// The box and the file as the plan's last proposal had them (a plan reopened shows what it
  /// was made with, not the settings), once per proposal: the user may change them after.
  void show_plan_model(const PlanState& state);
  void show_model_file(const QString& path);

  QLabel* proposal_note_;  ///< what the last proposal found
  QCheckBox* use_model_;   ///< guide the proposal with a model of the normal skull
  QLabel* model_file_;     ///< the model file chosen
  /// The model file of the plan's last proposal, used instead of the settings' while the box
  /// stays ticked (empty: the settings').
  QString plan_model_;
  std::string shown_proposal_;  ///< the proposal show_plan_model last followed
};

/// Step 6: surface markers on the mirror.
class SurfaceMarkersPage : public MarkersPage {
 public:
  explicit SurfaceMarkersPage(PageHost& host);
};

/// Step 7: the implant's method, resolution, thickness and fit to the bone.
class BuildPage : public StepPage {
 public:
  explicit BuildPage(PageHost& host);
  void show_state(const PlanState& state) override;
  void show_verdict(const QString& html) override;
  /// With "Mark a wider clearance" on, a click on the rim adds a clearance zone there.
  void surface_clicked(const Eigen::Vector3d& point) override;
  SkullView::PickTarget pick_target() const override;
  /// The implant's holes and tabs, each dragged to move it (one build per drop).
  std::vector<SkullView::Handle> handles(const PlanState& state) const override;
  void handle_dropped(int id, const Eigen::Vector3d& point) override;
  /// Where a tab's handle is drawn: on the bone just beyond its tip.
  static Eigen::Vector3d tab_handle(const Tab& tab);

 private:
  // The page's controls, added in this order by the constructor.
  void add_build_and_result();
  void add_shell_controls();
  void add_material_controls();
  void add_zone_controls();
  void add_perforation_controls();
  void add_tab_controls();
  /// Any control changed after a build marks the implant shown as not what the controls say.
  void watch_controls();
  ImplantParams params() const;
  /// The chosen preset's values into the fields (none: the fields off).
  void show_material(int index);
  /// Builds again with the page's parameters, when there is an implant to rebuild.
  void rebuild();

  QComboBox* method_;
  QDoubleSpinBox* resolution_;
  QDoubleSpinBox* thickness_;
  QDoubleSpinBox* fit_;
  QLabel* fit_note_;  ///< the margin the implant was fitted with, when not the one asked
  QComboBox* material_;
  QDoubleSpinBox *clearance_, *under_contour_, *min_thickness_, *plate_, *density_;
  QPushButton* mark_zone_;
  QDoubleSpinBox *zone_radius_, *zone_clearance_;
  QPushButton* remove_zone_;
  std::vector<ClearanceZone> zones_;
  QCheckBox* perforate_;
  QDoubleSpinBox *hole_diameter_, *hole_spacing_, *hole_edge_;
  QPushButton *add_hole_, *remove_hole_;
  std::vector<Eigen::Vector3d> added_holes_, removed_holes_;
  QCheckBox* tabs_;
  QSpinBox *tab_count_, *tab_screws_;
  QDoubleSpinBox* tab_length_;
  QPushButton *add_tab_, *remove_tab_;
  std::vector<Eigen::Vector3d> tab_positions_;  ///< the user's tabs (empty: evenly placed)
  /// The tabs as the user's: the ones shown (evenly placed ones included) when there are none.
  void take_tabs_over();
  /// Turns the other click modes off when one is turned on.
  void click_mode(QPushButton* on);
  /// A control changed since the implant shown was built: the page says Build applies it.
  void mark_changed();
  QLabel* info_;
  QLabel* changed_;  ///< "changed since the last build"
  QLabel* verdict_;  ///< the quality check's verdict on the implant shown
  QPushButton* build_;
  bool showing_ = false;  ///< show_state is setting the controls (not the user)
  const void* shown_implant_ = nullptr;
};

/// Step 8: Laplacian smoothing of the markers, previewed live, and marker edits.
class SmoothPage : public StepPage {
 public:
  explicit SmoothPage(PageHost& host);
  /// "Applied" stays for the state the smoothing made; another (an undo, an edit) clears it.
  void show_state(const PlanState& state) override;
  void surface_clicked(const Eigen::Vector3d& point) override;
  SkullView::PickTarget pick_target() const override;
  bool markers_editable() const override { return true; }

 protected:
  QString keys_hint() const override;

 private:
  Command smooth_command() const;
  void preview();

  QSlider* radius_;
  QSlider* weight_;
  QSpinBox* iterations_;
  QCheckBox* project_;
  QLabel* info_;
  QLabel* radius_value_;
  QLabel* weight_value_;
  bool applying_ = false;          ///< Apply pressed: the next state is the smoothing's
  const void* applied_ = nullptr;  ///< the state the smoothing made
};

/// Step 9: the quality report and export.
class ExportPage : public StepPage {
 public:
  explicit ExportPage(PageHost& host);
  void show_verdict(const QString& html) override;
  /// Whether (and by whom) the implant is approved, or why an approval was withdrawn.
  void show_state(const PlanState& state) override;
  void show_mould_message(const QString& text) override;

 private:
  QLabel* verdict_;
  QCheckBox* mould_;  ///< the 3MF export with a casting mould
  QLabel* mould_info_;
  QLabel* approval_;
};

}  // namespace cranioplan::gui
