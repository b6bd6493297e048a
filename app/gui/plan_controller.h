#pragma once
// The wizard's hold on its session: pushes commands (long ones computed off the GUI thread with
// Cancel), undo/redo, previews, saving, autosave. Like ParaView's pqUndoStack around
// vtkSMUndoStack: Qt signals around a session that knows nothing of Qt.
#include <QObject>
#include <QString>
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
  /// Replaces the plan (opened or recovered).
  void set_session(Session session);
  bool read_only() const { return read_only_; }
  void set_read_only(bool read_only) { read_only_ = read_only; }

  /// Runs a command now. Returns whether it was accepted; a refusal or a bad input is signalled.
  bool push(Command command);
  /// Runs a long command off the GUI thread; `busyChanged` brackets it. While busy, other
  /// pushes are refused.
  void push_async(Command command, const QString& what);
  /// Commands that take long enough to run off the GUI thread.
  static bool is_long(const Command& command);
  bool busy() const { return watcher_ != nullptr; }
  /// Drops the running computation's result: the plan stays as it was.
  void cancel();
  /// Waits (processing events) until no computation runs; for tests and the command line.
  void wait();

  /// The state the command would give, without recording it (live previews).
  std::shared_ptr<const PlanState> preview(const Command& command);

  void undo();
  void redo();
  void set_index(size_t index);

  void save(const QString& path);

 signals:
  void stateChanged();
  void refused(const QString& message);
  void failed(const QString& message);
  void busyChanged(bool busy, const QString& what);

 private:
  void finish();

  std::unique_ptr<Session> session_;
  QFutureWatcher<Computed>* watcher_ = nullptr;
  PreparedCommand running_;
  bool cancelled_ = false;
  bool read_only_ = false;
};

}  // namespace cranioplan::gui
