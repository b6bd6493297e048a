#pragma once
// The wizard's hold on its session: pushes commands (long ones computed off the GUI thread with
// Cancel), undo/redo, previews, saving, autosave. Like ParaView's pqUndoStack around
// vtkSMUndoStack: Qt signals around a session that knows nothing of Qt.
#include <QObject>
#include <QString>
#include <deque>
#include <memory>

#include "cranioplan/sessions/session.h"

template <typename T>
class QFutureWatcher;

namespace cranioplan::gui {

/// What a computation off the GUI thread gives back.
struct Computed {
  ApplyOutcome outcome;
  std::string error;  ///< a bad input (InputError) met while computing
};

class PlanController : public QObject {
  Q_OBJECT

 public:
  explicit PlanController(QObject* parent = nullptr);
  ~PlanController() override;

  Session& session() { return *session_; }
  const PlanState& state() const { return session_->state(); }
  /// Starts a new plan. Its journal is autosaved to `autosave_path` (empty: none).
  void new_session(const SessionInfo& info, const QString& autosave_path);
  /// Starts a new plan on trial: the plan open now is kept until the first long command (the
  /// skull's load) settles. Loaded, the old plan goes; failed, refused or cancelled, the old
  /// plan comes back as it was and the trial's autosave is removed (`trialSettled`).
  void try_new_session(const SessionInfo& info, const QString& autosave_path);
  /// A new plan is on trial; the window goes on showing the one open before until it settles.
  bool on_trial() const { return previous_ != nullptr; }
  /// Replaces the plan (opened or recovered).
  void set_session(Session session);
  bool read_only() const { return read_only_; }
  void set_read_only(bool read_only) { read_only_ = read_only; }

  /// Runs a command now (after the marker edits being computed, if any). Returns whether it was
  /// accepted; a refusal or a bad input is signalled.
  bool push(Command command);
  /// Runs a long command off the GUI thread; `busyChanged` brackets it. While busy, other
  /// pushes are refused.
  void push_async(Command command, const QString& what);
  /// The window's way in: runs the command now, or off the GUI thread when it is long in this
  /// state. While a marker edit is computed, further commands wait their turn in order (the
  /// hand goes on editing) and are refused otherwise.
  void submit(Command command, const QString& what = QString());
  /// Commands that take long enough to run off the GUI thread: the long ones, and marker edits
  /// in a plan whose implant is fitted to the bone (each rebuilds it).
  static bool is_long(const Command& command, const PlanState& state);
  /// Adding, moving, deleting or retyping a marker.
  static bool is_marker_edit(const Command& command);
  bool busy() const { return watcher_ != nullptr; }
  /// A marker edit is being computed (the window stays usable; further edits queue).
  bool editing() const { return busy() && running_edit_; }
  size_t queued() const { return queue_.size(); }
  /// Drops the running computation's result: the plan stays as it was. Queued edits go too.
  void cancel();
  /// Waits (processing events) until no computation runs; for tests and the command line.
  void wait();

  /// The state the command would give, without recording it (live previews).
  std::shared_ptr<const PlanState> preview(const Command& command);
  /// The same with the implant rebuilt quickly (live_preview_params: no fit to the bone),
  /// from what the view shows: for a marker while it is dragged.
  std::shared_ptr<const PlanState> preview_edit(const Command& command);
  /// What the view shows: the plan, or while marker edits are computed and queued, the plan
  /// as they will leave it with the implant previewed (the fitted one follows).
  const PlanState& shown_state() const;

  /// While marker edits are computed, undo takes back the last of them (queued, or the running
  /// one) instead of waiting.
  void undo();
  void redo();
  void set_index(size_t index);

  void save(const QString& path);

 signals:
  void stateChanged();
  void refused(const QString& message);
  void failed(const QString& message);
  void busyChanged(bool busy, const QString& what);
  /// A plan on trial settled: `loaded`, the new plan stays; otherwise the old one is back.
  void trialSettled(bool loaded);

 private:
  void finish();
  /// Cancels the running computation and drops the queue (the plan is being replaced).
  void drop_work();
  void start(Command command, const QString& what);
  void start_queued();
  /// The previews of the running and queued edits, from the plan as it stands.
  void update_intent();
  /// Ends a trial (try_new_session) as the new plan's state says.
  void settle_trial();

  struct Queued {
    Command command;
    QString what;
  };
  std::unique_ptr<Session> session_;
  std::unique_ptr<Session> previous_;  ///< the plan kept while a new one is on trial
  QFutureWatcher<Computed>* watcher_ = nullptr;
  PreparedCommand running_;
  bool running_edit_ = false;
  std::deque<Queued> queue_;
  std::shared_ptr<const PlanState> intent_;  ///< shown while edits are computed
  bool cancelled_ = false;
  bool read_only_ = false;
};

}  // namespace cranioplan::gui
