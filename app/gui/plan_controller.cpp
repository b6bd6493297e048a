#include "plan_controller.h"

#include <QCoreApplication>
#include <QFutureWatcher>
#include <QtConcurrent/QtConcurrentRun>

#include "cranioplan/model/error.h"

namespace cranioplan::gui {

PlanController::PlanController(QObject* parent)
    : QObject(parent), session_(std::make_unique<Session>()) {}

PlanController::~PlanController() {
  if (watcher_) watcher_->waitForFinished();
}

void PlanController::new_session(const SessionInfo& info, const QString& autosave_path) {
  session_ = std::make_unique<Session>(info);
  if (!autosave_path.isEmpty()) session_->set_autosave_path(autosave_path.toStdString());
  read_only_ = false;
  emit stateChanged();
}

void PlanController::set_session(Session session) {
  session_ = std::make_unique<Session>(std::move(session));
  emit stateChanged();
}

bool PlanController::is_long(const Command& c) {
  switch (c.type) {
    case CommandType::LoadSkull:
    case CommandType::AttachCt:
    case CommandType::FitPlane:
    case CommandType::AdjustPlane:
    case CommandType::Mirror:
    case CommandType::Register:
    case CommandType::MoveMirrored:
    case CommandType::ProposeMarkers:
    case CommandType::BuildImplant:
    case CommandType::SmoothMarkers:
      return true;
    case CommandType::ExportImplant:  // a mould takes seconds
      return c.params.contains("mould");
    default:
      return false;
  }
}

bool PlanController::push(Command command) {
  if (read_only_) {
    emit refused(tr("This plan is open for audit only."));
    return false;
  }
  if (busy()) {
    emit refused(tr("Wait for the running operation to finish (or cancel it)."));
    return false;
  }
  try {
    const PushResult r = session_->push(std::move(command));
    if (!r.accepted) {
      emit refused(QString::fromStdString(r.message));
      return false;
    }
  } catch (const Error& e) {
    emit failed(QString::fromUtf8(e.what()));
    return false;
  }
  emit stateChanged();
  return true;
}

void PlanController::push_async(Command command, const QString& what) {
  if (read_only_) {
    emit refused(tr("This plan is open for audit only."));
    return;
  }
  if (busy()) {
    emit refused(tr("Wait for the running operation to finish (or cancel it)."));
    return;
  }
  try {
    running_ = session_->prepare(std::move(command));
  } catch (const Error& e) {
    emit failed(QString::fromUtf8(e.what()));
    return;
  }
  if (!running_.ok) {
    emit refused(QString::fromStdString(running_.message));
    return;
  }
  cancelled_ = false;
  watcher_ = new QFutureWatcher<Computed>(this);
  connect(watcher_, &QFutureWatcher<Computed>::finished, this, &PlanController::finish);
  std::shared_ptr<const PlanState> state = session_->shared_state();
  const Command cmd = running_.command;
  const ApplyContext context = session_->context();
  watcher_->setFuture(QtConcurrent::run([state, cmd, context] {
    Computed c;
    try {
      c.outcome = apply_command(*state, cmd, context);
    } catch (const Error& e) {
      c.error = e.what();
    } catch (const std::exception& e) {
      c.error = std::string("unexpected error: ") + e.what();
    }
    return c;
  }));
  emit busyChanged(true, what);
}

void PlanController::finish() {
  Computed c = watcher_->result();
  watcher_->deleteLater();
  watcher_ = nullptr;
  const bool cancelled = cancelled_;
  emit busyChanged(false, QString());
  if (cancelled) return;
  if (!c.error.empty()) {
    emit failed(QString::fromStdString(c.error));
    return;
  }
  const PushResult r = session_->commit(running_, std::move(c.outcome));
  if (!r.accepted) {
    emit refused(QString::fromStdString(r.message));
    return;
  }
  emit stateChanged();
}

void PlanController::cancel() {
  if (busy()) cancelled_ = true;
}

void PlanController::wait() {
  while (busy()) QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
}

std::shared_ptr<const PlanState> PlanController::preview(const Command& command) {
  try {
    ApplyOutcome out = apply_command(session_->state(), command, session_->context());
    if (!out.accepted) return nullptr;
    return std::make_shared<const PlanState>(std::move(out.state));
  } catch (const Error&) {
    return nullptr;
  }
}

void PlanController::undo() {
  if (busy() || read_only_) return;
  if (session_->undo()) emit stateChanged();
}

void PlanController::redo() {
  if (busy() || read_only_) return;
  if (session_->redo()) emit stateChanged();
}

void PlanController::set_index(size_t index) {
  if (busy() || read_only_) return;  // audit views show state_at() instead
  session_->set_index(index);
  emit stateChanged();
}

void PlanController::save(const QString& path) {
  try {
    session_->save(path.toStdString());
    read_only_ = false;
  } catch (const Error& e) {
    emit failed(QString::fromUtf8(e.what()));
  }
  emit stateChanged();
}

}  // namespace cranioplan::gui
