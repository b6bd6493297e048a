#pragma once
// The wizard's window: the nine steps on the left (ticked, current, locked with the reason),
// the current step's instructions and page under them, the 3D view in the centre, the quality
// report, history and audit on the right, case and timers in the status bar; the menus,
// training and recovery. Each step's controls are its page (pages/step_pages.h); every action
// pushes a session command; the window computes no geometry.
#include <QElapsedTimer>
#include <QMainWindow>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "cranioplan/sessions/audit.h"
#include "pages/step_page.h"
#include "plan_controller.h"
#include "skull_view.h"
#include "slice_panel.h"

class QAction;
class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QListWidget;
class QProgressBar;
class QPushButton;
class QSlider;
class QSpinBox;
class QVBoxLayout;
class QFormLayout;
class QStackedWidget;
class QTableWidget;
class QTextBrowser;
class QTabWidget;
class QTimer;
template <typename T>
class QFutureWatcher;
class QMenu;
class QSplitter;

namespace cranioplan::gui {

class LoadPage;

class MainWindow : public QMainWindow, public PageHost {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  PlanController& controller() { return *controller_; }
  SkullView& view() override { return *view_; }
  SlicePanel& slices() { return *slices_; }
  /// What the centre shows: the 3D view, the 3D view with the three CT slices beside it, or
  /// the slices alone (View → Layout).
  enum class Layout { ThreeD, ThreeDAndSlices, Slices };
  void set_layout(Layout layout);
  /// View → Thickness map on or off.
  void set_thickness_map_shown(bool shown);
  /// The design report for sign-off at `html_path`, its pictures beside it (NAME_front.png,
  /// ...) and a PDF of it (NAME.pdf); false, with a message, without an implant or when a file
  /// cannot be written.
  bool write_design_report(const QString& html_path);
  Layout layout() const { return layout_; }
  void show_slices() override { set_layout(Layout::ThreeDAndSlices); }
  /// In step 9, the casting mould of the implant (made off the GUI thread) shown in the view.
  void show_mould(bool shown) override;
  /// Waits until the mould asked for is made and shown (tests).
  void wait_mould();

  // The pages' host.
  const PlanState& plan() const override { return controller_->state(); }
  void push(Command command, const QString& what = QString()) override;
  void show_message(const QString& text, bool problem) override;
  MarkerType marker_type() const override { return marker_type_; }
  /// The marker type that clicks place (keys 0–3).
  void set_marker_type(MarkerType type) override;
  void open_skull(const QString& path) override { open_input(path); }
  std::shared_ptr<const PlanState> preview(const Command& command) override;
  /// Markers from a file (.mrk.json, .json, .csv) as one import command.
  void import_markers(const QString& path) override;

  /// Without interaction, dialogs take their default answer (tests, --quit).
  void set_interactive(bool interactive) { interactive_ = interactive; }

  // What the menus and buttons do, callable from tests and the command line.
  void open_input(const QString& path, double threshold = std::numeric_limits<double>::quiet_NaN());
  /// The length unit meshes are read in (step 1's "Mesh units"): mm, cm, m, in or um; false
  /// for another name.
  bool set_mesh_unit(const std::string& name);
  // Which series of a DICOM folder to read (asked when it holds several); false: cancelled.
  bool choose_dicom_series(const QString& folder, ExtractBoneSurfaceParams& import);
  void open_sample() override;
  bool open_session(const QString& path);
  /// Shows the plan as it was when step `step` was current (commands of later steps undone).
  void replay_to_step(int step);
  bool save_session_to(const QString& path);
  bool export_to(const QString& path, bool with_mould = false) override;
  /// A CT for a plan made from a mesh (its bone surface at `threshold`, NaN: 300 HU or 0.5,
  /// must lie on the skull), shown in the slice views.
  void attach_ct(const QString& path, double threshold = std::numeric_limits<double>::quiet_NaN());
  /// Landmarks from a file (.mrk.json, .json): they replace the plan's, a command each.
  void import_landmarks(const QString& path);
  /// The implant as a labelmap (.nrrd) or 3D Slicer segmentation (.seg.nrrd) on the grid of
  /// the plan's CT.
  bool export_labelmap(const QString& path);
  /// The plan's markers or landmarks to a file (by extension: .mrk.json, .json, .csv).
  bool export_markers(const QString& path);
  bool export_landmarks(const QString& path);
  void open_audit(const QString& path);
  void start_training(const QString& reference_session);
  /// Unsaved plans of earlier runs that crashed; offers to recover the newest.
  void offer_recovery();
  /// The training report as HTML (empty when not training or not finished).
  QString training_report_html() const { return training_html_; }
  /// Waits (processing events) until the quality panel shows the current implant's report.
  void wait_quality();
  /// A picture of the whole window.
  QImage screenshot();

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  void build_menus();  // File, then the others
  void add_points_actions(QMenu* file);
  void add_slice_actions(QMenu* view);
  void build_edit_view_menus();
  void build_training_help_menus();
  void build_steps_dock();
  void build_plan_dock();
  void refresh();
  void refresh_steps();
  void refresh_history();
  void refresh_quality();
  void show_quality();
  void update_timers();
  void on_surface_clicked(const Eigen::Vector3d& point);
  void on_marker_dragged(int id, const Eigen::Vector3d& point);
  bool confirm_discard();
  void add_recent(const QString& path);
  void refresh_recent_menu();
  void finish_training_if_done();
  void show_training_report();
  QString autosave_folder() const;
  QString default_plan_name() const;

  PlanController* controller_;
  SkullView* view_;
  QSplitter* center_;
  SlicePanel* slices_;
  Layout layout_ = Layout::ThreeD;
  bool interactive_ = true;

  // Left: steps, instructions, pages.
  QListWidget* steps_ = nullptr;
  QLabel* instructions_ = nullptr;
  QStackedWidget* pages_ = nullptr;
  QPushButton* done_button_ = nullptr;
  int shown_step_ = 1;

  std::vector<StepPage*> step_pages_;  ///< steps 1–9, owned by pages_
  LoadPage* load_page_ = nullptr;
  MarkerType marker_type_ = MarkerType::OuterEdge;

  // Right: quality, history, audit.
  QTabWidget* plan_tabs_ = nullptr;
  QTextBrowser* quality_ = nullptr;
  QListWidget* history_ = nullptr;
  QWidget* audit_tab_ = nullptr;
  QSlider* audit_slider_ = nullptr;
  QLabel* audit_label_ = nullptr;
  QTextBrowser* audit_verify_ = nullptr;
  QTableWidget* audit_table_ = nullptr;

  // Status bar.
  QLabel* case_label_ = nullptr;
  QLabel* step_label_ = nullptr;
  QLabel* timer_label_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QPushButton* cancel_ = nullptr;
  QTimer* clock_ = nullptr;
  QTimer* quality_timer_ = nullptr;
  struct QualityView;
  QFutureWatcher<std::shared_ptr<QualityView>>* quality_watcher_ = nullptr;
  /// The mould shown in step 9: asked for, of which implant, and being made.
  bool mould_wanted_ = false;
  const void* mould_of_ = nullptr;
  QFutureWatcher<std::shared_ptr<const SkullView::PreparedMould>>* mould_watcher_ = nullptr;
  /// Makes or hides the mould as the state and the wish say.
  void update_mould();
  QElapsedTimer total_timer_, step_timer_;
  int timed_step_ = 0;

  QAction* undo_ = nullptr;
  QAction* redo_ = nullptr;
  QAction* show_mirror_ = nullptr;
  QAction* show_thickness_ = nullptr;
  class QMenu* recent_menu_ = nullptr;

  QString session_path_;
  std::string last_proposal_;
  QString training_reference_;
  QString training_html_;
};

}  // namespace cranioplan::gui
