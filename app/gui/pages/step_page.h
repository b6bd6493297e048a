#pragma once
// A wizard step's page: its controls, the commands they push, how clicks on the skull are read
// while the step is current, and the keys line under its instructions. A page computes no
// geometry and holds no plan: it pushes commands through its host (the main window) and shows
// the state it is given.
#include <QString>
#include <QWidget>
#include <memory>
#include <vector>

#include "cranioplan/sessions/command.h"
#include "cranioplan/sessions/plan_state.h"
#include "skull_view.h"

class QFormLayout;
class QLabel;
class QPushButton;
class QVBoxLayout;

namespace cranioplan::gui {

/// What a page may ask of the window that holds it.
class PageHost {
 public:
  virtual ~PageHost() = default;
  virtual const PlanState& plan() const = 0;
  /// Runs a command (long ones off the GUI thread, announced with `what`).
  virtual void push(Command command, const QString& what = QString()) = 0;
  virtual void show_message(const QString& text, bool problem) = 0;
  virtual SkullView& view() = 0;
  /// The marker type clicks place in steps 5, 6 and 8 (keys 0–3 choose it too).
  virtual MarkerType marker_type() const = 0;
  virtual void set_marker_type(MarkerType type) = 0;
  /// Opens a skull (mesh, CT, DICOM folder) as a new plan; asks the threshold for a CT.
  virtual void open_skull(const QString& path) = 0;
  virtual void open_sample() = 0;
  /// `with_mould`: a .3mf path, the package also holds a casting mould's halves.
  virtual bool export_to(const QString& path, bool with_mould = false) = 0;
  /// Shows the CT slices beside the 3D view.
  virtual void show_slices() = 0;
  /// The casting mould of the implant shown in the view (step 9) or hidden.
  virtual void show_mould(bool shown) = 0;
  /// Markers from a file (.mrk.json, .json, .csv), as one command.
  virtual void import_markers(const QString& path) = 0;
  /// `file_name` in the folder a save dialog should open in (beside the plan).
  virtual QString suggested_path(const QString& file_name) const = 0;
  /// The state a command would give, without recording it.
  virtual std::shared_ptr<const PlanState> preview(const Command& command) = 0;
};

class StepPage : public QWidget {
 public:
  StepPage(int step, PageHost& host, QWidget* parent = nullptr);

  int step() const { return step_; }
  /// The step's title, instructions, what is left to do, and the keys, as rich text.
  QString instructions_html(const PlanState& state) const;
  /// Shows the plan's state in the page's controls.
  virtual void show_state(const PlanState& state) { (void)state; }
  /// The quality check's verdict on the implant in a few lines (printable, or what is wrong and
  /// what to try), when it changes; the full table is the window's Quality panel.
  virtual void show_verdict(const QString& html) { (void)html; }
  /// What became of the casting mould asked for (its cavity's figures, or why there is none);
  /// empty: none shown.
  virtual void show_mould_message(const QString& text) { (void)text; }
  /// A click on the skull while this step is current.
  virtual void surface_clicked(const Eigen::Vector3d& point) { (void)point; }
  /// Which surface clicks place on while this step is current.
  virtual SkullView::PickTarget pick_target() const { return SkullView::PickTarget::None; }
  /// Whether markers can be dragged while this step is current.
  virtual bool markers_editable() const { return false; }
  /// What the user can drag in the view while this step is current, besides markers.
  virtual std::vector<SkullView::Handle> handles(const PlanState& state) const {
    (void)state;
    return {};
  }
  /// One of `handles()` dragged to `point` (on its surface) and let go.
  virtual void handle_dropped(int id, const Eigen::Vector3d& point) {
    (void)id;
    (void)point;
  }

 protected:
  /// The keys line under the instructions.
  virtual QString keys_hint() const;
  /// The keys line of the steps where markers are placed and moved.
  static QString marker_keys_hint();
  /// Where clicks place markers of a type: edges on the original skull, surfaces on the mirror.
  static SkullView::PickTarget marker_pick_target(MarkerType type);
  /// A push button with an object name (tests and style sheets find it by that name).
  QPushButton* make_button(const QString& text, const char* name);
  /// A button added as a row of the page's form.
  QPushButton* add_button(const QString& text, const char* name);
  /// A word-wrapped label's text, its height made room for at the page's width (again when the
  /// page is resized).
  void set_wrapped_text(QLabel* label, const QString& text);
  void resizeEvent(QResizeEvent* event) override;

  PageHost& host_;
  QVBoxLayout* layout_;  ///< the page, top to bottom
  QFormLayout* form_;    ///< the form at its top

 private:
  void fit_wrapped();
  int step_;
  std::vector<QLabel*> wrapped_;
};

/// The page of each wizard step (1–9).
std::unique_ptr<StepPage> make_step_page(int step, PageHost& host);

}  // namespace cranioplan::gui
