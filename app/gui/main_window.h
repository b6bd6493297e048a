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
class QScrollArea;
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
  /// What the centre shows: the 3D view alone, the 3D view and the three CT slices in four
  /// equal panes, or one pane maximised (View → Layout, each pane's ⤢ button).
  using Layout = SlicePanel::Arrangement;
  void set_layout(Layout layout);
  /// View → Thickness map on or off.
  void set_thickness_map_shown(bool shown);
  /// The design report for sign-off at `html_path`, its pictures beside it (NAME_front.png,
  /// ...) and a PDF of it (NAME.pdf); false, with a message, without an implant or when a file
  /// cannot be written.
  bool write_design_report(const QString& html_path);
  Layout layout() const { return layout_; }
  void show_slices() override { set_layout(Layout::FourUp); }
  /// In step 9, the casting mould of the implant (made off the GUI thread) shown in the view.
  void show_mould(bool shown) override;
  /// Waits until the mould asked for is made and shown (tests).
  void wait_mould();

  // The pages' host.
  const PlanState& plan() const override { return controller_->state(); }
  void push(Command command, const QString& what = QString()) override;
  void show_message(const QString& text, bool problem) override;
  /// What the window itself just did (undo, redo, save), in the status bar with a brief flash.
  void note_shown(const QString& text);
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
  /// Unsaved plans of earlier runs that crashed; offers to recover the newest, discard it for
  /// good, or leave it for later. `answer`: taken without asking (tests); none and not
  /// interactive: recovered.
  enum class RecoveryChoice { Recover, Discard, Later };
  void offer_recovery(std::optional<RecoveryChoice> answer = std::nullopt);
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
  /// Whether the quality check has refused the implant shown (false while it is computed).
  bool refused_implant() const;
  void show_quality();
  void update_timers();
  void on_surface_clicked(const Eigen::Vector3d& point);
  void on_marker_dragged(int id, const Eigen::Vector3d& point);
  /// Asks to save unsaved changes; false: cancelled. A plan discarded keeps its autosave until
  /// the plan replacing it is open (forget_discarded), so a bad file loses nothing.
  bool confirm_discard();
  void forget_discarded();
  void keep_discarded();
  void trial_settled(bool loaded);
  void add_recent(const QString& path);
  void refresh_recent_menu();
  void finish_training_if_done();
  void show_training_report();
  QString autosave_folder() const;
  QString default_plan_name() const;

 public:
  /// `file_name` in the folder a save dialog should open in: the plan's, else its skull's.
  QString suggested_path(const QString& file_name) const override;
  /// The folder of a file just written, for the next save dialog.
  void remember_dir(const QString& written);

 private:
  PlanController* controller_;
  SkullView* view_;
  SlicePanel* slices_;
  Layout layout_ = Layout::ThreeD;
  bool interactive_ = true;

  // Left: steps, instructions, pages.
  QListWidget* steps_ = nullptr;
  QLabel* instructions_ = nullptr;
  QStackedWidget* pages_ = nullptr;
  QPushButton* done_button_ = nullptr;
  QScrollArea* page_scroll_ = nullptr;
  int shown_step_ = 0;

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
  QAction* clip_ = nullptr;  ///< the clip plane applied to the view (on in step 4)
  /// The implant the quality check last judged, and whether it was printable.
  std::shared_ptr<const ImplantData> judged_implant_;
  bool judged_printable_ = true;
  std::optional<SoftTissueCheck> judged_tissue_;  ///< of that implant, with the plan's CT
  class QMenu* recent_menu_ = nullptr;

  QString session_path_;
  QString discarded_autosave_;  ///< of the plan discarded, removed once it is replaced
  QString trial_input_;         ///< the file being opened on trial
  std::string last_proposal_;
  QString training_reference_;
  QString training_html_;
};

}  // namespace cranioplan::gui
