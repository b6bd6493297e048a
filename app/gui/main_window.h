#pragma once
// The wizard's window: the nine steps on the left (ticked, current, locked with the reason),
// the current step's instructions and controls under them, the 3D view in the centre, the
// quality report and the history on the right, case and timers in the status bar. Every
// action pushes a session command; the window computes no geometry.
#include <QElapsedTimer>
#include <QMainWindow>
#include <limits>
#include <memory>
#include <optional>

#include "cranioplan/sessions/audit.h"
#include "plan_controller.h"
#include "skull_view.h"

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

namespace cranioplan::gui {

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  PlanController& controller() { return *controller_; }
  SkullView& view() { return *view_; }

  /// Without interaction, dialogs take their default answer (tests, --quit).
  void set_interactive(bool interactive) { interactive_ = interactive; }

  // What the menus and buttons do, callable from tests and the command line.
  void open_input(const QString& path, double threshold = std::numeric_limits<double>::quiet_NaN());
  /// The length unit meshes are read in (step 1's "Mesh units"): mm, cm, m, in or um; false
  /// for another name.
  bool set_mesh_unit(const std::string& name);
  // Which series of a DICOM folder to read (asked when it holds several); false: cancelled.
  bool choose_dicom_series(const QString& folder, ExtractBoneSurfaceParams& import);
  void open_sample();
  bool open_session(const QString& path);
  /// Shows the plan as it was when step `step` was current (commands of later steps undone).
  void replay_to_step(int step);
  bool save_session_to(const QString& path);
  bool export_to(const QString& path);
  void open_audit(const QString& path);
  void start_training(const QString& reference_session);
  /// Unsaved plans of earlier runs that crashed; offers to recover the newest.
  void offer_recovery();
  /// The marker type that clicks place (keys 0–3).
  void set_marker_type(MarkerType type);
  /// The training report as HTML (empty when not training or not finished).
  QString training_report_html() const { return training_html_; }
  /// A picture of the whole window.
  QImage screenshot();

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  void build_menus();  // File, then the others
  void build_edit_view_menus();
  void build_training_help_menus();
  void build_steps_dock();
  void build_plan_dock();
  QWidget* make_page(int step);
  // A step's page: the widget, its layout and the form at its top.
  struct PageParts {
    QWidget* page;
    QVBoxLayout* layout;
    QFormLayout* form;
  };
  void fill_load_page(const PageParts& p);
  void fill_plane_page(const PageParts& p);
  void fill_mirror_page(const PageParts& p);
  void fill_clip_page(const PageParts& p);
  void fill_markers_page(const PageParts& p, int step);
  void fill_build_page(const PageParts& p);
  void fill_smooth_page(const PageParts& p);
  void fill_export_page(const PageParts& p);
  void refresh();
  void refresh_steps();
  void refresh_history();
  void refresh_quality();
  void show_quality();
  void refresh_page();
  void update_timers();
  void on_surface_clicked(const Eigen::Vector3d& point);
  void on_marker_dragged(int id, const Eigen::Vector3d& point);
  void push(Command command, const QString& what = QString());
  void show_message(const QString& text, bool problem);
  bool confirm_discard();
  void add_recent(const QString& path);
  void refresh_recent_menu();
  void preview_smoothing();
  void finish_training_if_done();
  void show_training_report();
  QString autosave_folder() const;
  Command clip_command() const;

  PlanController* controller_;
  SkullView* view_;
  bool interactive_ = true;

  // Left: steps, instructions, pages.
  QListWidget* steps_ = nullptr;
  QLabel* instructions_ = nullptr;
  QStackedWidget* pages_ = nullptr;
  QPushButton* done_button_ = nullptr;
  int shown_step_ = 1;

  // Step controls.
  QDoubleSpinBox* threshold_ = nullptr;
  QComboBox* units_ = nullptr;  // a mesh file's length unit
  QLabel* skull_info_ = nullptr;
  QComboBox* landmark_ = nullptr;
  QLabel* plane_info_ = nullptr;
  QComboBox* adjust_axis_ = nullptr;
  QDoubleSpinBox* adjust_angle_ = nullptr;
  QDoubleSpinBox* adjust_shift_ = nullptr;
  QCheckBox* roi_only_ = nullptr;
  QDoubleSpinBox* roi_radius_ = nullptr;
  QLabel* register_info_ = nullptr;
  std::optional<Eigen::Vector3d> roi_center_;
  QCheckBox* clip_on_ = nullptr;
  QComboBox* clip_axis_ = nullptr;
  QSlider* clip_position_ = nullptr;
  QLabel* marker_counts_[2] = {nullptr, nullptr};
  QLabel* proposal_note_ = nullptr;  ///< step 5: what the last proposal found
  QComboBox* implant_method_ = nullptr;
  QDoubleSpinBox* implant_resolution_ = nullptr;
  QDoubleSpinBox* implant_thickness_ = nullptr;
  QDoubleSpinBox* implant_fit_ = nullptr;
  QLabel* implant_info_ = nullptr;
  QSlider* smooth_radius_ = nullptr;
  QSlider* smooth_weight_ = nullptr;
  QSpinBox* smooth_iterations_ = nullptr;
  QCheckBox* smooth_project_ = nullptr;
  QLabel* smooth_info_ = nullptr;
  QTextBrowser* export_report_ = nullptr;
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
  QElapsedTimer total_timer_, step_timer_;
  int timed_step_ = 0;

  QAction* undo_ = nullptr;
  QAction* redo_ = nullptr;
  QAction* show_mirror_ = nullptr;
  class QMenu* recent_menu_ = nullptr;

  QString session_path_;
  std::string last_proposal_;
  QString training_reference_;
  QString training_html_;
};

}  // namespace cranioplan::gui
