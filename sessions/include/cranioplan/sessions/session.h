#pragma once
// A planning session: the inputs, the effective command list (QUndoStack semantics: push runs a
// command; undo/redo move an index; a push after undo drops the redo branch; drags of one marker
// merge) and an append-only, hash-chained journal of every do, undo, redo and merge. State after
// each command is cached, so undo and redo are instant; the journal is appended to an autosave
// file after every command, so a crash loses no completed command.
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/sessions/command.h"
#include "cranioplan/sessions/plan_state.h"

namespace cranioplan {

/// The schema version this program writes. Older files are upgraded on reading.
constexpr int kSessionSchemaVersion = 2;

struct JournalEntry {
  int seq = 0;        ///< 1, 2, ...
  std::string event;  ///< "do", "undo", "redo" or "merge"
  std::string time;   ///< ISO-8601 UTC with milliseconds
  std::string user;
  int index = 0;                   ///< commands applied after the event
  std::optional<Command> command;  ///< do and merge: the command (merge: the merged one)
  std::string prev_hash;           ///< hash of the entry before (the genesis hash for seq 1)
  std::string hash;                ///< SHA-256 of prev_hash and this entry's other fields
};

/// Who made a session and for which case.
struct SessionInfo {
  std::string case_id;
  std::string user;     ///< empty: the login name
  std::string created;  ///< empty: now
};

struct SessionHeader {
  int schema_version = kSessionSchemaVersion;
  std::string app_version;
  SessionInfo info;
};

/// A session file as read, before anything is checked or replayed. `read_session_document`
/// throws SessionError for what makes it unreadable (not JSON, unknown schema version, unknown
/// command type, missing parameter); the hash chain and the replay are checked separately.
struct SessionDocument {
  std::string path;
  SessionHeader header;
  std::vector<Command> commands;       ///< the effective list
  std::vector<Command> redo_commands;  ///< undone commands still available to redo
  std::vector<JournalEntry> journal;
  Json raw;  ///< after upgrading to the current schema
};

SessionDocument read_session_document(const std::string& path);
/// Schema upgrades, one per version step; each takes and returns the whole document.
Json upgrade_v1_to_v2(Json document);

/// The hash that starts the chain: it binds the journal to the session's header.
std::string genesis_hash(const SessionHeader& header);
/// The hash an entry should carry, from its fields and its prev_hash.
std::string entry_hash(const JournalEntry& entry);
/// Index of the first entry whose prev_hash or hash does not hold; nullopt when the chain holds.
std::optional<size_t> first_broken_link(const SessionHeader& header,
                                        const std::vector<JournalEntry>& journal);
/// The command stack and index the journal's events produce. Throws SessionError (naming the
/// entry) for an event that cannot happen (undo with nothing to undo, ...).
struct Reconstruction {
  std::vector<Command> stack;
  size_t index = 0;
};
Reconstruction reconstruct(const std::vector<JournalEntry>& journal, const std::string& source);

/// A command checked against the step lock, with its live side effects done (skull hash
/// recorded, export written), ready to be computed off the GUI thread and committed.
struct PreparedCommand {
  bool ok = false;
  std::string message;  ///< why it is refused
  Command command;
  size_t index = 0;         ///< the session's index when prepared
  size_t journal_size = 0;  ///< the session's journal length when prepared
};

struct PushResult {
  bool accepted = false;
  bool merged = false;  ///< merged into the previous command (a drag)
  std::string message;
};

/// What an autosave file holds beyond a saved session.
struct RecoveryInfo {
  bool available = false;  ///< the autosave has completed commands the session file lacks
  int extra_events = 0;
  std::string last_time;  ///< time of the last recoverable event
  std::string autosave_path;
  std::string message;  ///< plain words, for a dialog
};

struct OpenOptions {
  /// Also take the events of a newer autosave file (recovery after a crash).
  bool recover_autosave = false;
  /// Append this session's new events to PATH.autosave (the wizard). Without it, opening
  /// writes nothing: replay, verify and audit leave the files as they are.
  bool attach_autosave = false;
  /// Called before each command is replayed with (commands replayed, commands in all), and
  /// once at the end; from the thread that opens.
  std::function<void(size_t done, size_t total)> progress;
};

class Session {
 public:
  explicit Session(SessionInfo info = {});
  ~Session();
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;

  /// Opens a saved session and replays it. Throws SessionError / InputError.
  static Session open(const std::string& path, const OpenOptions& options = {});
  /// Rebuilds a session from an autosave file alone (a plan that was never saved).
  static Session recover(const std::string& autosave_path);
  /// Whether `session_path`'s autosave holds more than the saved file.
  static RecoveryInfo recovery_info(const std::string& session_path);

  /// Runs a command of the current step (or an earlier one). A command of a locked step is
  /// refused with what is missing. Live side effects happen here, not on replay: the skull's
  /// SHA-256 is recorded, an export is written and its hash recorded.
  PushResult push(Command command);
  /// push() in three parts, for long operations: prepare on the GUI thread, compute
  /// `apply_command(state(), prepared.command, context())` anywhere (the state is immutable),
  /// commit on the GUI thread. A commit after the session changed is refused; dropping the
  /// outcome instead (Cancel) leaves the plan as it was.
  PreparedCommand prepare(Command command);
  PushResult commit(const PreparedCommand& prepared, ApplyOutcome outcome);
  const ApplyContext& context() const { return context_; }
  /// The state shared (for computing on another thread while this session stays as it is).
  std::shared_ptr<const PlanState> shared_state() const { return states_[index_]; }
  bool can_undo() const { return index_ > 0; }
  bool can_redo() const { return index_ < stack_.size(); }
  bool undo();
  bool redo();
  /// Undoes or redoes until `index` commands are applied (the history list's click).
  void set_index(size_t index);
  std::string undo_text() const;  ///< "Undo Move marker 12", or empty
  std::string redo_text() const;

  const PlanState& state() const;
  /// The state after the first `index` commands (audit slider). Cached or recomputed.
  const PlanState& state_at(size_t index);
  size_t index() const { return index_; }
  /// The whole stack: commands [0, index) are effective, the rest can be redone.
  const std::vector<Command>& stack() const { return stack_; }
  std::vector<Command> effective_commands() const;
  const std::vector<JournalEntry>& journal() const { return journal_; }
  const SessionHeader& header() const { return header_; }
  const std::string& path() const { return path_; }

  /// Writes the session atomically and marks it clean. A session that autosaves continues in
  /// `path` + ".autosave" from now on.
  void save(const std::string& path);
  /// True when the state equals the last saved one (drives "unsaved changes").
  bool is_clean() const { return clean_index_ && *clean_index_ == index_; }
  /// Appends every journal event to this file (and writes what the journal holds so far).
  void set_autosave_path(const std::string& path);
  const std::string& autosave_path() const { return autosave_path_; }
  /// The user recorded with each new command.
  void set_user(const std::string& user) { header_.info.user = user; }

  Json to_json() const;
  /// Cap on cached states besides the first (older ones are recomputed from the nearest one).
  void set_cache_limit(size_t limit) { cache_limit_ = limit; }
  /// Cap on the triangles of the distinct implants the cached states hold (an implant fitted to
  /// the bone has a hundred thousand or more; a plan edited for an hour would otherwise keep
  /// gigabytes). The states farthest from the current one go first.
  void set_cache_implant_triangles(size_t triangles) { cache_triangles_ = triangles; }
  /// Triangles of the distinct implants the cached states hold now.
  size_t cached_implant_triangles() const;

 private:
  void append_event(const std::string& event, const std::optional<Command>& command);
  void write_autosave_all();
  void append_autosave(const JournalEntry& entry);
  const PlanState& ensure_state(size_t index,
                                const std::function<void(size_t, size_t)>& progress = nullptr);
  void trim_cache();
  static Session from_journal(const SessionHeader& header, const std::vector<JournalEntry>& journal,
                              const std::string& source, const ApplyContext& context,
                              const std::function<void(size_t, size_t)>& progress = nullptr);

  SessionHeader header_;
  std::vector<Command> stack_;
  size_t index_ = 0;
  std::vector<std::shared_ptr<const PlanState>> states_;  ///< states_[i]: after i commands
  std::vector<JournalEntry> journal_;
  std::optional<size_t> clean_index_;
  std::string path_;
  std::string autosave_path_;
  std::FILE* autosave_ = nullptr;
  ApplyContext context_;
  size_t cache_limit_ = 200;
  size_t cache_triangles_ = 2'000'000;
};

/// Now as ISO-8601 UTC with milliseconds.
std::string now_iso8601();
/// Seconds since the epoch of a time as now_iso8601() writes it; NaN if malformed.
double parse_iso8601(const std::string& text);
/// The login name of the person running the program.
std::string login_name();

}  // namespace cranioplan
