// The commands table: Project::begin_command, Edit::commit, history, undo,
// redo and latest_result, and the revision every commit advances.
#include <sqlite3.h>

#include <cassert>

#include "core/errors.hpp"
#include "modeling/project.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kBumpRevision =
    "UPDATE meta SET value = CAST(value AS INTEGER) + 1 WHERE key = 'revision'";

constexpr const char* kSelectCommands =
    "SELECT id, name, settings, result, state, undoable, created_at FROM commands";

CommandRecord read_command(const sqlite::Statement& row) {
  CommandRecord record;
  record.id = row.column_int(0);
  record.name = row.column_text(1);
  record.settings = row.column_text(2);
  record.result = row.column_text(3);
  record.state = row.column_text(4) == "done" ? CommandState::kDone : CommandState::kUndone;
  record.undoable = row.column_int(5) != 0;
  record.created_at = row.column_text(6);
  return record;
}

// BEGIN IMMEDIATE … COMMIT for the journal's own small writes; rolled back
// unless committed.
class WriteLock {
 public:
  WriteLock(sqlite3* db, std::string file) : db_(db), file_(std::move(file)) {
    sqlite::execute(db_, "BEGIN IMMEDIATE", file_);
  }
  ~WriteLock() {
    if (db_ != nullptr && sqlite3_get_autocommit(db_) == 0) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    }
  }
  WriteLock(const WriteLock&) = delete;
  WriteLock& operator=(const WriteLock&) = delete;

  void commit() {
    sqlite::execute(db_, kBumpRevision, file_);
    sqlite::execute(db_, "COMMIT", file_);
    db_ = nullptr;
  }

 private:
  sqlite3* db_;
  std::string file_;
};

std::optional<CommandRecord> select_one(sqlite3* db, const std::string& file, const char* where) {
  const std::string sql = std::string(kSelectCommands) + " " + where;
  sqlite::Statement select(db, sql.c_str(), file);
  if (!select.step()) return std::nullopt;
  return read_command(select);
}

void set_state(sqlite3* db, const std::string& file, std::int64_t id, const char* state) {
  sqlite::Statement update(db, "UPDATE commands SET state = ?2 WHERE id = ?1", file);
  update.bind_int(1, id).bind_text(2, state).run();
}

}  // namespace

std::int64_t Project::revision() const {
  sqlite::Statement select(db(), "SELECT CAST(value AS INTEGER) FROM meta WHERE key = 'revision'",
                           file_name());
  if (!select.step()) {
    throw core::InputError(file_name(), {}, "project is damaged: no revision in table meta");
  }
  return select.column_int(0);
}

Project::Edit Project::begin_command(std::string_view name, const std::string& settings_json,
                                     std::optional<std::int64_t> based_on_revision) {
  assert(sqlite3_get_autocommit(db()) != 0 && "an Edit is already open on this project");
  sqlite::execute(db(), "BEGIN IMMEDIATE", file_name());
  Edit edit(db(), file_name(), 0);
  if (based_on_revision && revision() != *based_on_revision) {
    throw core::RuntimeFailure(file_name(), {},
                               "the project changed while " + std::string(name) +
                                   " was computing (another scanbench wrote to it); nothing was "
                                   "stored: run it again");
  }
  // A new command ends the redo branch: the undone commands and, by
  // cascade, every row they wrote are gone.
  sqlite::execute(db(), "DELETE FROM commands WHERE state = 'undone'", file_name());
  sqlite::Statement insert(
      db(), "INSERT INTO commands (name, settings, state, undoable) VALUES (?1, ?2, 'done', 1)",
      file_name());
  insert.bind_text(1, name).bind_text(2, settings_json).run();
  edit.command_id_ = sqlite3_last_insert_rowid(db());
  return edit;
}

void Project::Edit::commit(const std::string& result_json) {
  assert(active() && "commit on a committed or moved-from Edit");
  sqlite::Statement update(db_, "UPDATE commands SET result = ?2 WHERE id = ?1", file_);
  update.bind_int(1, command_id_).bind_text(2, result_json).run();
  sqlite::execute(db_, kBumpRevision, file_);
  sqlite::execute(db_, "COMMIT", file_);
  db_ = nullptr;
}

std::vector<CommandRecord> Project::history() const {
  const std::string sql = std::string(kSelectCommands) + " ORDER BY id";
  sqlite::Statement select(db(), sql.c_str(), file_name());
  std::vector<CommandRecord> records;
  while (select.step()) records.push_back(read_command(select));
  return records;
}

std::optional<CommandRecord> Project::undo() {
  assert(sqlite3_get_autocommit(db()) != 0 && "undo while an Edit is open");
  WriteLock lock(db(), file_name());
  std::optional<CommandRecord> last =
      select_one(db(), file_name(), "WHERE state = 'done' ORDER BY id DESC LIMIT 1");
  if (!last || !last->undoable) return std::nullopt;
  set_state(db(), file_name(), last->id, "undone");
  lock.commit();
  last->state = CommandState::kUndone;
  return last;
}

std::optional<CommandRecord> Project::redo() {
  assert(sqlite3_get_autocommit(db()) != 0 && "redo while an Edit is open");
  WriteLock lock(db(), file_name());
  std::optional<CommandRecord> next =
      select_one(db(), file_name(), "WHERE state = 'undone' ORDER BY id LIMIT 1");
  if (!next) return std::nullopt;
  set_state(db(), file_name(), next->id, "done");
  lock.commit();
  next->state = CommandState::kDone;
  return next;
}

std::optional<std::string> Project::latest_result(std::string_view name) const {
  sqlite::Statement select(db(),
                           "SELECT result FROM commands WHERE name = ?1 AND state = 'done' "
                           "ORDER BY id DESC LIMIT 1",
                           file_name());
  select.bind_text(1, name);
  if (!select.step()) return std::nullopt;
  return select.column_text(0);
}

}  // namespace scanbench::modeling
