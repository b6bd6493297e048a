#include "cranioplan/sessions/session.h"

#include <pwd.h>
#include <unistd.h>

#include <cassert>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <unordered_set>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/sessions/session_error.h"
#include "cranioplan/sessions/sha256.h"

#ifndef CRANIOPLAN_VERSION
#define CRANIOPLAN_VERSION "0"
#endif

namespace cranioplan {

namespace fs = std::filesystem;

std::string now_iso8601() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[96];
  std::snprintf(buf, sizeof(buf), "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

double parse_iso8601(const std::string& text) {
  std::tm tm{};
  int ms = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                  &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &ms) < 6)
    return std::numeric_limits<double>::quiet_NaN();
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(timegm(&tm)) + ms / 1000.0;
}

std::string login_name() {
  if (const char* u = std::getenv("CRANIOPLAN_USER"); u && *u) return u;
  if (const passwd* pw = getpwuid(getuid()); pw && pw->pw_name) return pw->pw_name;
  if (const char* u = std::getenv("USER"); u && *u) return u;
  return "unknown";
}

// ---------------------------------------------------------------------------------------------
// Journal entries and the hash chain

namespace {

Json entry_body(const JournalEntry& e) {
  Json j;
  j["seq"] = e.seq;
  j["event"] = e.event;
  j["time"] = e.time;
  j["user"] = e.user;
  j["index"] = e.index;
  if (e.command) j["command"] = to_json(*e.command);
  j["prev_hash"] = e.prev_hash;
  return j;
}

Json entry_to_json(const JournalEntry& e) {
  Json j = entry_body(e);
  j["hash"] = e.hash;
  return j;
}

JournalEntry entry_from_json(const Json& j, const std::string& where) {
  if (!j.is_object()) throw SessionError(where, "a journal entry must be a JSON object");
  const ParamReader r(j, where);
  JournalEntry e;
  e.seq = r.integer("seq");
  e.event = r.string("event");
  if (e.event != "do" && e.event != "undo" && e.event != "redo" && e.event != "merge")
    throw SessionError(where, "unknown journal event \"" + e.event + "\"");
  e.time = r.string("time");
  e.user = r.string("user");
  e.index = r.integer("index");
  if (e.event == "do" || e.event == "merge")
    e.command = command_from_json(r.value("command"), where + " command");
  e.prev_hash = r.string("prev_hash");
  e.hash = r.string("hash");
  return e;
}

Json header_identity(const SessionHeader& h) {
  return Json{{"case_id", h.info.case_id}, {"created", h.info.created}, {"user", h.info.user}};
}

}  // namespace

std::string genesis_hash(const SessionHeader& header) {
  return sha256_hex(header_identity(header).dump());
}

std::string entry_hash(const JournalEntry& entry) { return sha256_hex(entry_body(entry).dump()); }

std::optional<size_t> first_broken_link(const SessionHeader& header,
                                        const std::vector<JournalEntry>& journal) {
  std::string prev = genesis_hash(header);
  for (size_t i = 0; i < journal.size(); ++i) {
    const JournalEntry& e = journal[i];
    if (e.seq != static_cast<int>(i) + 1 || e.prev_hash != prev || entry_hash(e) != e.hash)
      return i;
    prev = e.hash;
  }
  return std::nullopt;
}

Reconstruction reconstruct(const std::vector<JournalEntry>& journal, const std::string& source) {
  Reconstruction r;
  for (const auto& e : journal) {
    const std::string where = source + ": journal entry " + std::to_string(e.seq);
    if (e.event == "do") {
      r.stack.resize(r.index);
      r.stack.push_back(*e.command);
      ++r.index;
    } else if (e.event == "undo") {
      if (r.index == 0) throw SessionError(where, "undo with nothing to undo");
      --r.index;
    } else if (e.event == "redo") {
      if (r.index >= r.stack.size()) throw SessionError(where, "redo with nothing to redo");
      ++r.index;
    } else {  // merge
      if (r.index == 0) throw SessionError(where, "merge with no command to merge into");
      r.stack[r.index - 1] = *e.command;
    }
    if (static_cast<int>(r.index) != e.index)
      throw SessionError(where, "records " + std::to_string(e.index) +
                                    " applied commands, but its events give " +
                                    std::to_string(r.index));
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Documents and schema versions

Json upgrade_v1_to_v2(Json d) {
  // Version 1 (Cranioplan 0.1 development files): "case" instead of "case_id", "app" as
  // "cranioplan X.Y.Z", no "inputs" and no "redo_commands" (the journal holds them).
  Json out;
  out["schema_version"] = 2;
  std::string app = d.value("app", std::string());
  const std::string prefix = "cranioplan ";
  out["app_version"] = app.rfind(prefix, 0) == 0 ? app.substr(prefix.size()) : app;
  out["case_id"] = d.value("case", std::string());
  out["user"] = d.value("user", std::string());
  out["created"] = d.value("created", std::string());
  Json inputs = Json::array();
  if (d.contains("commands") && d["commands"].is_array())
    for (const auto& c : d["commands"])
      if (c.is_object() && c.value("type", std::string()) == "load_skull" && c.contains("params"))
        inputs.push_back({{"role", "skull"},
                          {"path", c["params"].value("path", std::string())},
                          {"sha256", c["params"].value("sha256", std::string())}});
  out["inputs"] = inputs;
  out["commands"] = d.value("commands", Json::array());
  out["redo_commands"] = nullptr;  // derived from the journal
  out["journal"] = d.value("journal", Json::array());
  return out;
}

SessionDocument read_session_document(const std::string& path) {
  SessionDocument doc;
  doc.path = path;
  Json j = read_json_file(path);
  if (!j.is_object()) throw SessionError(path, "a session must be a JSON object");
  if (!j.contains("schema_version") || !j["schema_version"].is_number_integer())
    throw SessionError(path, "not a Cranioplan session (no \"schema_version\")");
  const int version = j["schema_version"].get<int>();
  if (version < 1 || version > kSessionSchemaVersion)
    throw SessionError(path, "unknown session schema version " + std::to_string(version) +
                                 " (this program reads 1 to " +
                                 std::to_string(kSessionSchemaVersion) + ")");
  if (version == 1) j = upgrade_v1_to_v2(std::move(j));
  const ParamReader r(j, path);
  doc.header.schema_version = kSessionSchemaVersion;
  doc.header.app_version = r.string("app_version");
  doc.header.info.case_id = r.string("case_id");
  doc.header.info.user = r.string("user");
  doc.header.info.created = r.string("created");
  auto commands = [&](const char* name, std::vector<Command>& out) {
    const Json& list = r.value(name);
    if (list.is_null()) return;
    if (!list.is_array()) throw SessionError(path, std::string("\"") + name + "\" must be a list");
    for (size_t i = 0; i < list.size(); ++i)
      out.push_back(command_from_json(list[i], path + ": " + name + "[" + std::to_string(i) + "]"));
  };
  commands("commands", doc.commands);
  commands("redo_commands", doc.redo_commands);
  const Json& journal = r.value("journal");
  if (!journal.is_array()) throw SessionError(path, "\"journal\" must be a list");
  for (size_t i = 0; i < journal.size(); ++i)
    doc.journal.push_back(
        entry_from_json(journal[i], path + ": journal entry " + std::to_string(i + 1)));
  doc.raw = std::move(j);
  return doc;
}

namespace {

// Checks the chain and that the document's command lists are what its journal gives.
Reconstruction check_document(const SessionDocument& doc) {
  if (auto bad = first_broken_link(doc.header, doc.journal))
    throw SessionError(doc.path, "the hash chain breaks at journal entry " +
                                     std::to_string(*bad + 1) +
                                     ": the session was changed after it was written");
  Reconstruction rec = reconstruct(doc.journal, doc.path);
  const std::vector<Command> effective(rec.stack.begin(), rec.stack.begin() + rec.index);
  auto same = [](const std::vector<Command>& a, const std::vector<Command>& b, size_t& at) {
    for (at = 0; at < std::min(a.size(), b.size()); ++at)
      if (to_json(a[at]) != to_json(b[at])) return false;
    return a.size() == b.size();
  };
  size_t at = 0;
  if (!same(doc.commands, effective, at))
    throw SessionError(doc.path, "commands[" + std::to_string(at) +
                                     "] is not what the journal recorded: the session was "
                                     "changed after it was written");
  const bool has_redo = doc.raw.contains("redo_commands") && !doc.raw["redo_commands"].is_null();
  const std::vector<Command> redo(rec.stack.begin() + rec.index, rec.stack.end());
  if (has_redo && !same(doc.redo_commands, redo, at))
    throw SessionError(
        doc.path, "redo_commands[" + std::to_string(at) + "] is not what the journal recorded");
  return rec;
}

struct Autosave {
  SessionHeader header;
  std::vector<JournalEntry> entries;  ///< the complete, chained ones
  std::string note;                   ///< why reading stopped early, if it did
};

std::optional<Autosave> read_autosave(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  Autosave a;
  if (!std::getline(in, line)) return std::nullopt;
  Json head = Json::parse(line, nullptr, false);
  if (!head.is_object() || !head.contains("cranioplan_autosave"))
    throw SessionError(path, "not a Cranioplan autosave file");
  a.header.app_version = head.value("app_version", std::string());
  a.header.info.case_id = head.value("case_id", std::string());
  a.header.info.user = head.value("user", std::string());
  a.header.info.created = head.value("created", std::string());
  std::string prev = genesis_hash(a.header);
  while (std::getline(in, line)) {
    if (in.eof()) {  // no newline: the line was being written when the program stopped
      a.note = "the last event was cut off while it was being written";
      break;
    }
    Json j = Json::parse(line, nullptr, false);
    if (j.is_discarded()) {
      a.note = "event " + std::to_string(a.entries.size() + 1) + " is unreadable";
      break;
    }
    JournalEntry e;
    try {
      e = entry_from_json(j, path);
    } catch (const SessionError& err) {
      a.note = err.what();
      break;
    }
    if (e.prev_hash != prev || entry_hash(e) != e.hash ||
        e.seq != static_cast<int>(a.entries.size()) + 1) {
      a.note = "event " + std::to_string(a.entries.size() + 1) + " breaks the hash chain";
      break;
    }
    prev = e.hash;
    a.entries.push_back(std::move(e));
  }
  return a;
}

std::string autosave_for(const std::string& session_path) { return session_path + ".autosave"; }

// What the autosave beside `session_path` holds beyond the saved journal `saved`.
RecoveryInfo recovery_beyond(const std::string& session_path,
                             const std::vector<JournalEntry>& saved) {
  RecoveryInfo info;
  info.autosave_path = autosave_for(session_path);
  const auto a = read_autosave(info.autosave_path);
  if (!a || a->entries.size() <= saved.size()) return info;
  for (size_t i = 0; i < saved.size(); ++i)
    if (a->entries[i].hash != saved[i].hash) {
      info.message = "the autosave belongs to a different version of this plan";
      return info;
    }
  info.available = true;
  info.extra_events = static_cast<int>(a->entries.size() - saved.size());
  info.last_time = a->entries.back().time;
  info.message = std::to_string(info.extra_events) +
                 " change(s) made after the plan was last saved can be recovered (the last at " +
                 info.last_time + ")";
  if (!a->note.empty()) info.message += "; " + a->note;
  return info;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Session

Session::Session(SessionInfo info) {
  header_.app_version = CRANIOPLAN_VERSION;
  header_.info = std::move(info);
  if (header_.info.user.empty()) header_.info.user = login_name();
  if (header_.info.created.empty()) header_.info.created = now_iso8601();
  states_.push_back(std::make_shared<const PlanState>());
}

Session::~Session() {
  if (autosave_) std::fclose(autosave_);
}

Session::Session(Session&& o) noexcept { *this = std::move(o); }

Session& Session::operator=(Session&& o) noexcept {
  if (this == &o) return *this;
  if (autosave_) std::fclose(autosave_);
  header_ = std::move(o.header_);
  stack_ = std::move(o.stack_);
  index_ = o.index_;
  states_ = std::move(o.states_);
  journal_ = std::move(o.journal_);
  clean_index_ = o.clean_index_;
  path_ = std::move(o.path_);
  autosave_path_ = std::move(o.autosave_path_);
  autosave_ = o.autosave_;
  o.autosave_ = nullptr;
  context_ = std::move(o.context_);
  cache_limit_ = o.cache_limit_;
  return *this;
}

const PlanState& Session::state() const {
  assert(states_[index_] && "the current state is always cached");
  return *states_[index_];
}

std::vector<Command> Session::effective_commands() const {
  return {stack_.begin(), stack_.begin() + static_cast<std::ptrdiff_t>(index_)};
}

const PlanState& Session::ensure_state(size_t index,
                                       const std::function<void(size_t, size_t)>& progress) {
  assert(index <= stack_.size());
  if (states_[index]) return *states_[index];
  size_t from = index;
  while (!states_[from]) --from;  // states_[0] is always there
  for (size_t i = from; i < index; ++i) {
    if (progress) progress(i, index);
    ApplyOutcome out = apply_command(*states_[i], stack_[i], context_);
    if (!out.accepted)
      throw SessionError(path_.empty() ? "session" : path_,
                         "command " + std::to_string(i + 1) + " (" + describe(stack_[i]) +
                             ") is refused on replay: " + out.message);
    states_[i + 1] = std::make_shared<const PlanState>(std::move(out.state));
  }
  if (progress) progress(index, index);
  return *states_[index];
}

const PlanState& Session::state_at(size_t index) {
  const PlanState& s = ensure_state(std::min(index, stack_.size()));
  trim_cache();
  return s;
}

size_t Session::cached_implant_triangles() const {
  // Unchanged states share one implant: each is counted once.
  std::unordered_set<const ImplantData*> seen;
  size_t total = 0;
  for (size_t i = 1; i < states_.size(); ++i)
    if (states_[i] && states_[i]->implant && seen.insert(states_[i]->implant.get()).second)
      total += states_[i]->implant->result().mesh.n_faces();
  return total;
}

void Session::trim_cache() {
  size_t cached = 0;
  for (size_t i = 1; i < states_.size(); ++i) cached += states_[i] != nullptr;
  while (cached > cache_limit_ || cached_implant_triangles() > cache_triangles_) {
    size_t far = 0, far_distance = 0;
    for (size_t i = 1; i < states_.size(); ++i) {
      if (!states_[i] || i == index_) continue;
      const size_t d = i > index_ ? i - index_ : index_ - i;
      if (d > far_distance) far = i, far_distance = d;
    }
    if (far == 0) break;
    states_[far].reset();
    --cached;
  }
}

PreparedCommand Session::prepare(Command command) {
  PreparedCommand p;
  p.index = index_;
  p.journal_size = journal_.size();
  const PlanState& before = state();
  command.meta.step = command_step(before, command);
  command.meta.user = header_.info.user;
  if (command.meta.started.empty()) command.meta.started = now_iso8601();
  std::string why;
  if (command.meta.step >= kLoadStep && !step_unlocked(before, command.meta.step, &why)) {
    p.message = why;
    return p;
  }
  // Live side effects: what replay checks rather than repeats.
  if (command.type == CommandType::LoadSkull || command.type == CommandType::AttachCt) {
    const std::string path = command.params.value("path", std::string());
    std::error_code ec;
    const fs::path absolute = fs::absolute(path, ec);
    if (!ec) command.params["path"] = absolute.lexically_normal().string();
    if (command.params.value("sha256", std::string()).empty())
      command.params["sha256"] = sha256_file(command.params["path"].get<std::string>());
  } else if (command.type == CommandType::Approve) {
    // What is approved: the implant as it stands.
    if (before.implant && command.params.value("implant_sha256", std::string()).empty())
      command.params["implant_sha256"] = before.implant->stl_sha256();
  } else if (command.type == CommandType::ExportImplant) {
    if (!before.implant) {
      p.message = "there is no implant to export: build it first";
      return p;
    }
    const std::string path = command.params.value("path", std::string());
    ExportSpec spec;
    spec.format = command.params.value("format", std::string("stl"));
    // A 3MF carries the plan's hash as it stands before the export.
    if (spec.format == "3mf")
      command.params["plan_sha256"] = spec.plan_sha256 =
          journal_.empty() ? genesis_hash(header_) : journal_.back().hash;
    if (command.params.contains("mould"))
      spec.mould = mould_from_json(ParamReader(command.params["mould"], "export_implant mould"));
    std::string why;
    const std::string bytes = export_bytes(before, spec, &why);
    if (!why.empty()) {
      p.message = why;
      return p;
    }
    write_file_atomically(path, bytes);
    command.params["sha256"] = sha256_hex(bytes);
  }
  p.ok = true;
  p.command = std::move(command);
  return p;
}

PushResult Session::push(Command command) {
  const auto t0 = std::chrono::steady_clock::now();
  // A search the caller ran for the command before pushing it (autoplan_session records the
  // plan's stages so) is part of the command's time.
  const double searched_ms = std::max(0.0, command.meta.duration_ms);
  PreparedCommand prepared = prepare(std::move(command));
  if (!prepared.ok) return PushResult{false, false, prepared.message};
  ApplyOutcome out = apply_command(state(), prepared.command, context_);
  prepared.command.meta.duration_ms =
      searched_ms +
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return commit(prepared, std::move(out));
}

PushResult Session::commit(const PreparedCommand& prepared, ApplyOutcome out) {
  PushResult result;
  if (!prepared.ok || prepared.index != index_ || prepared.journal_size != journal_.size()) {
    result.message = "the plan changed while the operation ran; run it again";
    return result;
  }
  if (!out.accepted) {
    result.message = out.message;
    return result;
  }
  Command command = prepared.command;
  // What the command found that a replay must reuse (a proposal's markers) becomes part of it,
  // and so of what the journal's hashes cover.
  for (const auto& [key, value] : out.record.items()) command.params[key] = value;
  command.meta.ended = now_iso8601();
  if (command.meta.duration_ms <= 0.0) {
    const double span = parse_iso8601(command.meta.ended) - parse_iso8601(command.meta.started);
    command.meta.duration_ms = std::isfinite(span) ? std::max(0.0, span * 1000.0) : 0.0;
  }
  result.accepted = true;
  result.message = out.message;

  // QUndoStack: drop the redo branch, then merge with the top command when both move the same
  // marker (a drag) and the top is not the saved state.
  stack_.resize(index_);
  states_.resize(index_ + 1);
  if (clean_index_ && *clean_index_ > index_) clean_index_.reset();
  const bool merge = index_ > 0 && command.type == CommandType::MoveMarker &&
                     stack_[index_ - 1].type == CommandType::MoveMarker &&
                     stack_[index_ - 1].params.value("id", -1) == command.params.value("id", -2) &&
                     !(clean_index_ && *clean_index_ == index_);
  if (merge) {
    Command merged = command;
    merged.meta.started = stack_[index_ - 1].meta.started;
    merged.meta.duration_ms += stack_[index_ - 1].meta.duration_ms;
    // The state after the merged command is the state after both: a move sets the position.
    stack_[index_ - 1] = merged;
    states_[index_] = std::make_shared<const PlanState>(std::move(out.state));
    append_event("merge", merged);
    result.merged = true;
  } else {
    stack_.push_back(command);
    states_.push_back(std::make_shared<const PlanState>(std::move(out.state)));
    ++index_;
    append_event("do", command);
  }
  trim_cache();
  return result;
}

bool Session::undo() {
  if (!can_undo()) return false;
  ensure_state(index_ - 1);
  --index_;
  append_event("undo", std::nullopt);
  trim_cache();
  return true;
}

bool Session::redo() {
  if (!can_redo()) return false;
  ensure_state(index_ + 1);
  ++index_;
  append_event("redo", std::nullopt);
  trim_cache();
  return true;
}

void Session::set_index(size_t index) {
  index = std::min(index, stack_.size());
  while (index_ > index) undo();
  while (index_ < index) redo();
}

std::string Session::undo_text() const {
  return can_undo() ? "Undo " + describe(stack_[index_ - 1]) : std::string();
}

std::string Session::redo_text() const {
  return can_redo() ? "Redo " + describe(stack_[index_]) : std::string();
}

void Session::append_event(const std::string& event, const std::optional<Command>& command) {
  JournalEntry e;
  e.seq = static_cast<int>(journal_.size()) + 1;
  e.event = event;
  e.time = now_iso8601();
  e.user = header_.info.user;
  e.index = static_cast<int>(index_);
  e.command = command;
  e.prev_hash = journal_.empty() ? genesis_hash(header_) : journal_.back().hash;
  e.hash = entry_hash(e);
  journal_.push_back(e);
  if (autosave_) append_autosave(e);
}

void Session::append_autosave(const JournalEntry& entry) {
  const std::string line = entry_to_json(entry).dump() + "\n";
  if (std::fwrite(line.data(), 1, line.size(), autosave_) != line.size() ||
      std::fflush(autosave_) != 0)
    throw InputError(autosave_path_, "cannot append to the autosave file (disk full?)");
  fdatasync(fileno(autosave_));
}

void Session::write_autosave_all() {
  Json head;
  head["cranioplan_autosave"] = 1;
  head["schema_version"] = kSessionSchemaVersion;
  head["app_version"] = header_.app_version;
  head["case_id"] = header_.info.case_id;
  head["user"] = header_.info.user;
  head["created"] = header_.info.created;
  std::string bytes = head.dump() + "\n";
  for (const auto& e : journal_) bytes += entry_to_json(e).dump() + "\n";
  write_file_atomically(autosave_path_, bytes);
  if (autosave_) std::fclose(autosave_);
  autosave_ = std::fopen(autosave_path_.c_str(), "ab");
  if (!autosave_) throw InputError(autosave_path_, "cannot open the autosave file for writing");
}

void Session::set_autosave_path(const std::string& path) {
  autosave_path_ = path;
  write_autosave_all();
}

Json Session::to_json() const {
  Json j;
  j["schema_version"] = kSessionSchemaVersion;
  j["app_version"] = header_.app_version;
  j["case_id"] = header_.info.case_id;
  j["user"] = header_.info.user;
  j["created"] = header_.info.created;
  Json inputs = Json::array();
  for (size_t i = 0; i < index_; ++i)
    if (stack_[i].type == CommandType::LoadSkull || stack_[i].type == CommandType::AttachCt)
      inputs.push_back({{"role", stack_[i].type == CommandType::LoadSkull ? "skull" : "ct"},
                        {"path", stack_[i].params["path"]},
                        {"sha256", stack_[i].params["sha256"]}});
  j["inputs"] = inputs;
  Json commands = Json::array(), redo = Json::array();
  for (size_t i = 0; i < stack_.size(); ++i)
    (i < index_ ? commands : redo).push_back(cranioplan::to_json(stack_[i]));
  j["commands"] = commands;
  j["redo_commands"] = redo;
  Json journal = Json::array();
  for (const auto& e : journal_) journal.push_back(entry_to_json(e));
  j["journal"] = journal;
  return j;
}

void Session::save(const std::string& path) {
  write_json_file(to_json(), path);
  path_ = path;
  context_.session_dir = fs::path(path).parent_path().string();
  clean_index_ = index_;
  // A session that autosaves (the wizard's) keeps doing so, now beside its file.
  if (!autosave_path_.empty()) {
    autosave_path_ = autosave_for(path);
    write_autosave_all();
  }
}

Session Session::from_journal(const SessionHeader& header, const std::vector<JournalEntry>& journal,
                              const std::string& source, const ApplyContext& context,
                              const std::function<void(size_t, size_t)>& progress) {
  Session s;
  s.header_ = header;
  s.header_.app_version = CRANIOPLAN_VERSION;
  s.context_ = context;
  Reconstruction rec = reconstruct(journal, source);
  s.stack_ = std::move(rec.stack);
  s.states_.assign(s.stack_.size() + 1, nullptr);
  s.states_[0] = std::make_shared<const PlanState>();
  s.journal_ = journal;
  s.path_ = source;
  s.index_ = rec.index;
  s.ensure_state(s.index_, progress);
  s.trim_cache();
  return s;
}

Session Session::open(const std::string& path, const OpenOptions& options) {
  const SessionDocument doc = read_session_document(path);
  check_document(doc);
  ApplyContext context;
  context.session_dir = fs::path(path).parent_path().string();
  std::vector<JournalEntry> journal = doc.journal;
  bool recovered = false;
  if (options.recover_autosave || options.attach_autosave) {
    const RecoveryInfo info = recovery_beyond(path, doc.journal);
    if (info.available && options.recover_autosave) {
      journal = read_autosave(info.autosave_path)->entries;
      recovered = true;
    } else if (info.available) {
      // Declined: keep the unsaved changes beside the plan rather than overwrite them.
      std::error_code ec;
      fs::rename(info.autosave_path, info.autosave_path + ".declined", ec);
    }
  }
  Session s = from_journal(doc.header, journal, path, context, options.progress);
  s.header_.app_version = doc.header.app_version;
  if (!recovered) s.clean_index_ = s.index_;
  if (options.attach_autosave) {
    s.autosave_path_ = autosave_for(path);
    s.write_autosave_all();
  }
  return s;
}

Session Session::recover(const std::string& autosave_path) {
  const auto a = read_autosave(autosave_path);
  if (!a) throw InputError(autosave_path, "the autosave file is missing or empty");
  ApplyContext context;
  context.session_dir = fs::path(autosave_path).parent_path().string();
  Session s = from_journal(a->header, a->entries, autosave_path, context);
  s.path_.clear();
  s.autosave_path_ = autosave_path;
  s.write_autosave_all();
  return s;
}

RecoveryInfo Session::recovery_info(const std::string& session_path) {
  std::error_code ec;
  return recovery_beyond(session_path, fs::exists(session_path, ec)
                                           ? read_session_document(session_path).journal
                                           : std::vector<JournalEntry>{});
}

}  // namespace cranioplan
