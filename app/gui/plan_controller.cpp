#include "plan_controller.h"

#include <QCoreApplication>
#include <QFutureWatcher>
#include <QtConcurrent/QtConcurrentRun>
#include <cstdio>

#include "cranioplan/model/error.h"
#include "cranioplan/sessions/previews.h"

namespace cranioplan::gui {

PlanController::PlanController(QObject* parent)
    : QObject(parent), session_(std::make_unique<Session>()) {}

PlanController::~PlanController() {
  if (watcher_) watcher_->waitForFinished();
}

void PlanController::drop_work() {
  if (busy()) cancelled_ = true;  // its result belongs to the plan being replaced
  queue_.clear();
  intent_.reset();
}

void PlanController::new_session(const SessionInfo& info, const QString& autosave_path) {
  drop_work();
  previous_.reset();
  session_ = std::make_unique<Session>(info);
  if (!autosave_path.isEmpty()) session_->set_autosave_path(autosave_path.toStdString());
  read_only_ = false;
  emit stateChanged();
}

void PlanController::try_new_session(const SessionInfo& info, const QString& autosave_path) {
  drop_work();
  // A second trial before the first settled keeps the first's old plan; its own session goes.
  const std::string abandoned = previous_ ? session_->autosave_path() : std::string();
  if (!previous_) previous_ = std::move(session_);
  // The new plan replaces the open one only once it has loaded: on trial meanwhile, so that
  // the window goes on showing the plan open before (no state change is announced now).
  session_ = std::make_unique<Session>(info);
  if (!autosave_path.isEmpty()) session_->set_autosave_path(autosave_path.toStdString());
  read_only_ = false;
  if (!abandoned.empty()) std::remove(abandoned.c_str());
}

void PlanController::settle_trial() {
  if (!previous_ || busy()) return;
  const bool loaded = session_->state().skull != nullptr;
  if (loaded) {
    previous_.reset();
  } else {
    const std::string autosave = session_->autosave_path();
    session_ = std::move(previous_);  // the trial's session closes its autosave file
    if (!autosave.empty()) std::remove(autosave.c_str());
  }
  emit stateChanged();  // the window shows the plan that stays
  emit trialSettled(loaded);
}

void PlanController::set_session(Session session) {
  drop_work();
  previous_.reset();
  session_ = std::make_unique<Session>(std::move(session));
  emit stateChanged();
}

bool PlanController::is_marker_edit(const Command& c) {
  return c.type == CommandType::AddMarker || c.type == CommandType::MoveMarker ||
         c.type == CommandType::DeleteMarker || c.type == CommandType::RetypeMarker;
}

bool PlanController::is_long(const Command& c, const PlanState& state) {
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
    case CommandType::AddMarker:  // the implant follows the markers: fitted, in a second
    case CommandType::MoveMarker:
    case CommandType::DeleteMarker:
    case CommandType::RetypeMarker:
    case CommandType::ImportMarkers:
    case CommandType::ClearMarkers:
      return state.implant_params && state.implant_params->fit_to_bone_mm > 0.0;
    default:
      return false;
  }
}

bool PlanController::push(Command command) {
  if (read_only_) {
    emit refused(tr("This plan is open for audit only."));
    return false;
  }
  if (editing()) wait();  // after the marker edits given so far, as a queued command would run
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
  running_edit_ = is_marker_edit(running_.command);
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
  // What the view shows meanwhile: this edit and those queued behind it, previewed.
  update_intent();
  emit busyChanged(true, what);
}

void PlanController::submit(Command command, const QString& what) {
  if (read_only_) {
    emit refused(tr("This plan is open for audit only."));
    return;
  }
  if (editing()) {
    if (is_marker_edit(command))
      if (auto next = preview_command_quickly(shown_state(), command, session_->context()))
        intent_ = std::move(next);
    queue_.push_back({std::move(command), what});
    emit stateChanged();
    return;
  }
  start(std::move(command), what);
}

void PlanController::start(Command command, const QString& what) {
  if (is_long(command, state()))
    push_async(std::move(command),
               what.isEmpty() ? QString::fromStdString(describe(command)) : what);
  else
    push(std::move(command));
  if (!busy()) settle_trial();  // refused before it started
}

void PlanController::start_queued() {
  while (!busy() && !queue_.empty()) {
    Queued next = std::move(queue_.front());
    queue_.pop_front();
    start(std::move(next.command), next.what);
  }
}

void PlanController::update_intent() {
  intent_.reset();
  if (!editing()) return;
  std::shared_ptr<const PlanState> at;
  auto add = [&](const Command& c) {
    if (!is_marker_edit(c)) return;
    if (auto next = preview_command_quickly(at ? *at : state(), c, session_->context()))
      at = std::move(next);
  };
  if (!cancelled_) add(running_.command);
  for (const Queued& q : queue_) add(q.command);
  intent_ = std::move(at);
}

const PlanState& PlanController::shown_state() const {
  return intent_ && busy() ? *intent_ : state();
}

std::shared_ptr<const PlanState> PlanController::preview_edit(const Command& command) {
  return preview_command_quickly(shown_state(), command, session_->context());
}

void PlanController::finish() {
  Computed c = watcher_->result();
  watcher_->deleteLater();
  watcher_ = nullptr;
  const bool cancelled = cancelled_;
  running_edit_ = false;
  if (!cancelled) {
    if (!c.error.empty()) {
      emit failed(QString::fromStdString(c.error));
    } else {
      const PushResult r = session_->commit(running_, std::move(c.outcome));
      if (!r.accepted) emit refused(QString::fromStdString(r.message));
    }
  }
  // The next queued command starts on the plan as this one left it (a refused or failed edit
  // leaves the plan as it was; those queued after it still run).
  start_queued();
  if (!busy()) {
    intent_.reset();
    emit busyChanged(false, QString());
  }
  emit stateChanged();
  settle_trial();
}

void PlanController::cancel() {
  if (!busy()) return;
  cancelled_ = true;
  queue_.clear();
  update_intent();
  emit stateChanged();
}

void PlanController::wait() {
  while (busy()) QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
}

std::shared_ptr<const PlanState> PlanController::preview(const Command& command) {
  return preview_command(session_->state(), command, session_->context());
}

void PlanController::undo() {
  if (read_only_) return;
  if (editing()) {  // the last edit given: queued, or the one being computed
    if (!queue_.empty())
      queue_.pop_back();
    else
      cancelled_ = true;
    update_intent();
    emit stateChanged();
    return;
  }
  if (busy()) return;
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
  if (editing()) wait();  // the marker edits given so far are part of what is saved
  try {
    session_->save(path.toStdString());
    read_only_ = false;
  } catch (const Error& e) {
    emit failed(QString::fromUtf8(e.what()));
  }
  emit stateChanged();
}

}  // namespace cranioplan::gui
