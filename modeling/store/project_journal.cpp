// The commands table: Project::begin_command, begin_long_command, the
// Edit's commits, history, undo and redo (which verify what they make
// current), latest_result, the revision every commit advances, read
// snapshots, and batches of commands in one transaction.
#include <sqlite3.h>

#include <cassert>
#include <set>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/process.hpp"
#include "modeling/store/checksummed_rows.hpp"
#include "modeling/store/object_tree_cache.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {
namespace {

constexpr const char* kBumpRevision =
    "UPDATE meta SET value = CAST(value AS INTEGER) + 1 WHERE key = 'revision'";

const std::string kSelectCommands = sql_of({"SELECT ", kCommandColumns, " FROM commands"});

// The next place in the journal.
constexpr const char* kNextSeq = "(SELECT coalesce(max(seq), 0) + 1 FROM commands)";

// Stores the checksum of command `id` as it now stands.
void update_checksum(sqlite3* db, const std::string& file, std::int64_t id) {
  const std::string sql = kSelectCommands + " WHERE id = ?1";
  sqlite::Statement select(db, sql.c_str(), file);
  select.bind_int(1, id);
  if (!select.step()) return;
  const CommandFields fields = read_command_fields(select).first;
  sqlite::Statement update(db, "UPDATE commands SET checksum = ?2 WHERE id = ?1", file);
  update.bind_int(1, id).bind_int(2, checksum(fields)).run();
}

CommandRecord read_command(const sqlite::Statement& row, const std::string& file) {
  const auto [fields, stored] = read_command_fields(row);
  if (checksum(fields) != stored) {
    core::FilePosition position;
    position.detail = "command " + std::to_string(fields.id);
    throw core::InputError(file, position,
                           "project is damaged: the journal entry fails its checksum "
                           "(changed outside scanbench?)");
  }
  CommandRecord record;
  record.id = fields.id;
  record.name = fields.name;
  record.settings = fields.settings;
  record.result = fields.result;
  record.state = fields.state == "done"     ? CommandState::kDone
                 : fields.state == "undone" ? CommandState::kUndone
                                            : CommandState::kPending;
  record.undoable = fields.undoable != 0;
  record.created_at = row.column_text(7);
  return record;
}

std::optional<CommandRecord> select_one(sqlite3* db, const std::string& file, const char* where) {
  const std::string sql = kSelectCommands + " " + where;
  sqlite::Statement select(db, sql.c_str(), file);
  if (!select.step()) return std::nullopt;
  return read_command(select, file);
}

std::int64_t read_revision(sqlite3* db, const std::string& file) {
  sqlite::Statement select(db, "SELECT CAST(value AS INTEGER) FROM meta WHERE key = 'revision'",
                           file);
  if (!select.step()) {
    throw core::InputError(file, {}, "project is damaged: no revision in table meta");
  }
  return select.column_int(0);
}

// The revision at which `data` last changed: 0 when no command since
// scanbench began keeping it has written it.
std::int64_t changed_at(sqlite3* db, const std::string& file, ProjectData data) {
  sqlite::Statement select(db, "SELECT CAST(value AS INTEGER) FROM meta WHERE key = ?1", file);
  select.bind_text(1, std::string("changed.") + data_key(data));
  return select.step() ? select.column_int(0) : 0;
}

// Refuses command `name`, computed on the project as it was at revision
// `based_on`, when a command since then changed data it read.
void check_revision(sqlite3* db, const std::string& file, std::string_view name,
                    std::optional<std::int64_t> based_on) {
  if (!based_on || read_revision(db, file) == *based_on) return;
  for (const ProjectData data : data_in(footprint_of(name).reads)) {
    if (changed_at(db, file, data) <= *based_on) continue;
    throw core::RuntimeFailure(file, {},
                               "the project's " + std::string(data_name(data)) + " changed while " +
                                   std::string(name) +
                                   " was computing (another scanbench wrote them); nothing was "
                                   "stored: run it again");
  }
}

// True when pending command `id` was begun by a process of this machine
// that is gone. Only processes of this machine (host, boot, pid namespace)
// can be judged; other machines' commands are never taken for gone.
bool writer_is_gone(sqlite3* db, const std::string& file, std::int64_t id) {
  sqlite::Statement select(
      db, "SELECT owner_machine, owner_pid, owner_start FROM commands WHERE id = ?1", file);
  select.bind_int(1, id);
  if (!select.step() || select.is_null(0)) return false;
  const std::string machine = select.column_text(0);
  return machine == core::this_process().machine &&
         !core::is_running({machine, select.column_int(1), select.column_int(2)});
}

// Removes pending commands (with their rows) whose process is gone: what a
// killed long command left.
void remove_abandoned(sqlite3* db, const std::string& file) {
  std::vector<std::int64_t> abandoned;
  for (sqlite::Statement select(db, "SELECT id FROM commands WHERE state = 'pending'", file);
       select.step();) {
    if (writer_is_gone(db, file, select.column_int(0))) abandoned.push_back(select.column_int(0));
  }
  for (const std::int64_t id : abandoned) {
    sqlite::Statement remove(db, "DELETE FROM commands WHERE id = ?1", file);
    remove.bind_int(1, id).run();
  }
}

// A new command ends the redo branch: the undone commands and, by cascade,
// every row they wrote are gone.
void end_redo_branch(sqlite3* db, const std::string& file) {
  sqlite::execute(db, "DELETE FROM commands WHERE state = 'undone'", file);
}

void set_state(sqlite3* db, const std::string& file, std::int64_t id, const char* state) {
  sqlite::Statement update(db, "UPDATE commands SET state = ?2 WHERE id = ?1", file);
  update.bind_int(1, id).bind_text(2, state).run();
  update_checksum(db, file, id);
}

}  // namespace

std::int64_t Project::revision() const {
  return read_revision(db(), file_name());
}

std::int64_t Project::changed_at(ProjectData data) const {
  return store::changed_at(db(), file_name(), data);
}

Project::Edit Project::begin_command(std::string_view name, const std::string& settings_json,
                                     std::optional<std::int64_t> based_on_revision) {
  Edit edit(db(), file_name(), 0, Edit::Kind::kCommand, connection_.get());
  edit.writes_ = footprint_of(name).writes;
  check_revision(db(), file_name(), name, based_on_revision);
  remove_abandoned(db(), file_name());
  end_redo_branch(db(), file_name());
  const std::string sql = std::string(
                              "INSERT INTO commands (seq, name, settings, state, undoable) "
                              "VALUES (") +
                          kNextSeq + ", ?1, ?2, 'done', 1)";
  sqlite::Statement insert(db(), sql.c_str(), file_name());
  insert.bind_text(1, name).bind_text(2, settings_json).run();
  edit.command_id_ = sqlite3_last_insert_rowid(db());
  update_checksum(db(), file_name(), edit.command_id_);
  return edit;
}

Project::LongCommand Project::begin_long_command(std::string_view name,
                                                 const std::string& settings_json,
                                                 std::optional<std::int64_t> based_on_revision) {
  assert(!connection_->batch && "a long command inside a Batch");
  Edit edit(db(), file_name(), 0, Edit::Kind::kPart, connection_.get());
  check_revision(db(), file_name(), name, based_on_revision);
  remove_abandoned(db(), file_name());
  sqlite::Statement insert(db(),
                           "INSERT INTO commands (name, settings, state, undoable, owner_machine, "
                           "owner_pid, owner_start) VALUES (?1, ?2, 'pending', 1, ?3, ?4, ?5)",
                           file_name());
  const core::ProcessIdentity self = core::this_process();
  insert.bind_text(1, name).bind_text(2, settings_json).bind_text(3, self.machine);
  insert.bind_int(4, self.pid).bind_int(5, self.start_ticks).run();
  const std::int64_t id = sqlite3_last_insert_rowid(db());
  update_checksum(db(), file_name(), id);
  edit.commit_part();
  return LongCommand(*this, id, std::string(name), based_on_revision);
}

Project::LongCommand::LongCommand(LongCommand&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)),
      file_(std::move(other.file_)),
      connection_(other.connection_),
      command_id_(other.command_id_),
      name_(std::move(other.name_)),
      revision_(other.revision_) {}

Project::LongCommand::~LongCommand() {
  if (db_ == nullptr || sqlite3_get_autocommit(db_) == 0) return;
  // Abandoned: remove the pending command and its rows. Best effort: what
  // a failure leaves is removed by the next writer once this process is gone.
  if (sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr) != SQLITE_OK) return;
  const std::string sql =
      "DELETE FROM commands WHERE state = 'pending' AND id = " + std::to_string(command_id_);
  const bool removed = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK;
  sqlite3_exec(db_, removed ? "COMMIT" : "ROLLBACK", nullptr, nullptr, nullptr);
}

Project::Edit Project::LongCommand::part() {
  assert(db_ != nullptr && !connection_->batch &&
         "part of a moved-from LongCommand, or in a Batch");
  Edit edit(db_, file_, command_id_, Edit::Kind::kPart, connection_);
  if (!select_one(db_, file_,
                  ("WHERE state = 'pending' AND id = " + std::to_string(command_id_)).c_str())) {
    throw core::RuntimeFailure(file_, {},
                               name_ +
                                   " was removed from the project by another scanbench "
                                   "while it was being written; nothing was stored");
  }
  return edit;
}

Project::Edit Project::LongCommand::finish() {
  Edit edit = part();
  edit.kind_ = Edit::Kind::kFinal;
  edit.writes_ = footprint_of(name_).writes;
  check_revision(db_, file_, name_, revision_);
  remove_abandoned(db_, file_);
  end_redo_branch(db_, file_);
  return edit;
}

void Project::Edit::commit(const std::string& result_json) {
  assert(active() && (kind_ == Kind::kCommand || kind_ == Kind::kFinal) &&
         "commit on a committed, moved-from or part Edit");
  const std::string sql =
      std::string(
          "UPDATE commands SET result = ?2, state = 'done', seq = "
          "coalesce(seq, ") +
      kNextSeq + "), owner_machine = NULL, owner_pid = NULL, owner_start = NULL WHERE id = ?1";
  sqlite::Statement update(db_, sql.c_str(), file_);
  update.bind_int(1, command_id_).bind_text(2, result_json).run();
  update_checksum(db_, file_, command_id_);
  finish_transaction();
}

void Project::Edit::commit_part() {
  assert(active() && kind_ == Kind::kPart && "commit_part on a committed or whole-command Edit");
  finish_transaction();
}

void Project::Edit::finish_transaction() {
  std::optional<std::int64_t> before;
  if (kind_ != Kind::kPart) {
    before = read_revision(db_, file_);
    sqlite::execute(db_, kBumpRevision, file_);
    for (const ProjectData data : data_in(writes_)) {
      sqlite::Statement mark(db_, "INSERT OR REPLACE INTO meta (key, value) VALUES (?1, ?2)",
                             file_);
      mark.bind_text(1, std::string("changed.") + data_key(data));
      mark.bind_text(2, std::to_string(*before + 1)).run();
    }
  }
  sqlite::execute(db_, nested_ ? "RELEASE edit" : "COMMIT", file_);
  db_ = nullptr;
  connection_->edit = false;
  // A whole command's nodes follow into the tree; an undo or redo changes
  // versions without writing nodes, and a long command's parts stay unseen
  // until it finishes: then the tree is read again.
  if (kind_ == Kind::kCommand) {
    connection_->tree.committed(*before);
  } else {
    connection_->tree.forget();
  }
}

void Project::require_open_batch(sqlite3* db, ConnectionState& connection,
                                 const std::string& file) {
  if (sqlite3_get_autocommit(db) == 0 && !connection.batch_failed) return;
  throw core::RuntimeFailure(file, {},
                             "a write failed earlier and SQLite rolled the whole batch back; "
                             "nothing was stored");
}

std::vector<CommandRecord> Project::history() const {
  const std::string sql = kSelectCommands + " ORDER BY seq IS NULL, seq, id";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  std::vector<CommandRecord> records;
  while (select.step()) records.push_back(read_command(select, file_name()));
  for (CommandRecord& record : records) {
    if (record.state == CommandState::kPending && writer_is_gone(db(), file_name(), record.id))
      record.state = CommandState::kInterrupted;
  }
  return records;
}

std::optional<CommandRecord> Project::undo(std::optional<std::int64_t> only) {
  Edit journal(db(), file_name(), 0, Edit::Kind::kJournal, connection_.get());
  std::optional<CommandRecord> last =
      select_one(db(), file_name(), "WHERE state = 'done' ORDER BY seq DESC LIMIT 1");
  if (!last || !last->undoable || (only && last->id != *only)) return std::nullopt;
  journal.writes_ = footprint_of(last->name).writes;
  set_state(db(), file_name(), last->id, "undone");
  verify_current_rows(last->id);
  journal.finish_transaction();
  last->state = CommandState::kUndone;
  return last;
}

std::optional<CommandRecord> Project::redo(std::optional<std::int64_t> only) {
  Edit journal(db(), file_name(), 0, Edit::Kind::kJournal, connection_.get());
  std::optional<CommandRecord> next =
      select_one(db(), file_name(), "WHERE state = 'undone' ORDER BY seq LIMIT 1");
  if (!next || (only && next->id != *only)) return std::nullopt;
  journal.writes_ = footprint_of(next->name).writes;
  set_state(db(), file_name(), next->id, "done");
  verify_current_rows(next->id);
  journal.finish_transaction();
  next->state = CommandState::kDone;
  return next;
}

void Project::verify_current_rows(std::int64_t command_id) const {
  std::set<std::int64_t> live;
  for (const StoredScanSummary& scan : scans()) live.insert(scan.id);  // records and poses
  static_cast<void>(object_nodes());
  static_cast<void>(scan_color_corrections());
  static_cast<void>(scan_sources());
  static_cast<void>(images(true));
  sqlite::Statement layers(
      db(), "SELECT DISTINCT scan_id, name FROM scan_layers WHERE command_id = ?1", file_name());
  layers.bind_int(1, command_id);
  while (layers.step()) {
    if (live.count(layers.column_int(0)) != 0)
      verify_current_layer(layers.column_int(0), layers.column_text(1));
  }
}

std::optional<std::string> Project::latest_result(std::string_view name) const {
  const std::string sql =
      kSelectCommands + " WHERE name = ?1 AND state = 'done' ORDER BY seq DESC LIMIT 1";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_text(1, name);
  if (!select.step()) return std::nullopt;
  return read_command(select, file_name()).result;  // verified
}

std::optional<CommandRecord> Project::layer_writer(std::int64_t id, std::string_view name) const {
  const std::string sql = kSelectCommands + R"sql( WHERE id = (
  SELECT l.command_id FROM scan_layers l JOIN commands c ON c.id = l.command_id
  WHERE l.scan_id = ?1 AND l.name = ?2 AND c.state = 'done'
  ORDER BY c.seq DESC LIMIT 1))sql";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  select.bind_int(1, id).bind_text(2, name);
  if (!select.step()) return std::nullopt;
  return read_command(select, file_name());  // verified
}

Project::ReadSnapshot Project::read_snapshot() const {
  assert(!connection_->edit && !connection_->snapshot && "a snapshot inside an Edit or another");
  if (connection_->batch) return ReadSnapshot(nullptr, nullptr);  // one state already
  sqlite::execute(db(), "BEGIN DEFERRED", file_name());
  ReadSnapshot snapshot(db(), connection_.get());
  // Under write-ahead logging the snapshot is taken at the first read.
  static_cast<void>(read_revision(db(), file_name()));
  return snapshot;
}

Project::Batch Project::begin_batch() {
  assert(!connection_->batch && !connection_->edit && !connection_->snapshot &&
         "a Batch inside an Edit, a snapshot or a Batch");
  sqlite::execute(db(), "BEGIN IMMEDIATE", file_name());
  connection_->batch = true;
  connection_->batch_failed = false;
  return Batch(db(), file_name(), connection_.get());
}

void Project::Batch::commit() {
  assert(db_ != nullptr && !connection_->edit &&
         "commit of a finished Batch, or with an Edit open");
  require_open_batch(db_, *connection_, file_);
  sqlite::execute(db_, "COMMIT", file_);
  db_ = nullptr;
  connection_->batch = false;
}

Project::Batch::~Batch() {
  roll_back();
}

void Project::Batch::roll_back() noexcept {
  if (db_ == nullptr) return;
  if (sqlite3_get_autocommit(db_) == 0) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  db_ = nullptr;
  connection_->batch = false;
  // The revision goes back, and another process may reach the same number
  // with another tree: what the batch's commands cached is forgotten.
  connection_->tree.forget();
}

Project::ReadSnapshot::~ReadSnapshot() {
  if (connection_ != nullptr) connection_->snapshot = false;
  if (db_ != nullptr && sqlite3_get_autocommit(db_) == 0) {
    sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr);
  }
}

}  // namespace scanbench::store
