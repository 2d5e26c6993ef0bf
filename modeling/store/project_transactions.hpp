// Project's transactions (project.hpp): the Edit every write goes through,
// a LongCommand written in parts, a ReadSnapshot, a Batch of commands in
// one transaction, and a Draft of a new project. Included by project.hpp;
// include that one.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "modeling/store/command_footprint.hpp"
#include "modeling/store/project.hpp"

struct sqlite3;

namespace scanbench::store {

// One write transaction of a command: everything written through the
// Project with this Edit lands in the file together, or not at all. Rolled
// back on destruction unless committed. Must not outlive its Project. The
// writing methods of Project take an Edit, so no write can happen outside one.
class Project::Edit {
 public:
  Edit(Edit&& other) noexcept;
  Edit& operator=(Edit&& other) noexcept;
  ~Edit();

  // The journal id of the command; rows written through this Edit carry it.
  std::int64_t command_id() const { return command_id_; }

  // For begin_command's Edit and LongCommand::finish's: stores `result_json`
  // as the command's result, makes the command done (a long one now takes
  // its place in the journal), and makes everything durable. Asserts the
  // edit is open and of that kind. Throws core::RuntimeFailure when SQLite
  // cannot commit (I/O error, disk full); the changes are then rolled back
  // when the Edit is destroyed.
  void commit(const std::string& result_json);

  // For LongCommand::part's Edit: makes the part durable; its rows stay
  // invisible until the command finishes. Throws as commit.
  void commit_part();

  // False once committed or moved from.
  bool active() const { return db_ != nullptr; }

 private:
  friend class Project;
  enum class Kind { kCommand, kPart, kFinal, kJournal };
  // Opens the write transaction: BEGIN IMMEDIATE, or a savepoint inside a
  // Batch. Asserts no other Edit is open; throws core::RuntimeFailure when
  // the lock is held too long.
  Edit(sqlite3* db, std::string file, std::int64_t command_id, Kind kind, ConnectionState* open);
  // Advances the revision (all but parts), records it as the last change
  // of each kind of data in writes_, and commits, or releases the
  // savepoint inside a Batch.
  void finish_transaction();
  void roll_back() noexcept;

  sqlite3* db_ = nullptr;
  std::string file_;
  std::int64_t command_id_ = 0;
  Kind kind_ = Kind::kCommand;
  bool nested_ = false;  // a savepoint of a Batch
  ProjectDataSet writes_ = 0;  // what the command (or the one undone or redone) changes
  ConnectionState* connection_ = nullptr;
};

// A pending command written in parts. Abandoned (removed with its rows) on
// destruction unless finished. Must not outlive its Project.
class Project::LongCommand {
 public:
  LongCommand(LongCommand&& other) noexcept;
  LongCommand& operator=(LongCommand&&) = delete;
  ~LongCommand();

  std::int64_t command_id() const { return command_id_; }

  // Opens the write transaction of the next part (BEGIN IMMEDIATE). Throws
  // core::RuntimeFailure when the command is gone (removed as abandoned) or
  // the lock is held too long. Asserts no Edit is open.
  Edit part();

  // Opens the last transaction: checks the revision the command was begun
  // on (core::RuntimeFailure, and nothing becomes visible, when another
  // process changed data the command reads), ends the redo branch, and returns the
  // Edit whose commit() makes the command done. The caller may write
  // through it first. Once the returned Edit commits, the command is no
  // longer abandoned on destruction.
  Edit finish();

 private:
  friend class Project;
  LongCommand(const Project& project, std::int64_t command_id, std::string name,
              std::optional<std::int64_t> revision)
      : db_(project.db()),
        file_(project.file_name()),
        connection_(project.connection_.get()),
        command_id_(command_id),
        name_(std::move(name)),
        revision_(revision) {}

  sqlite3* db_ = nullptr;
  std::string file_;
  ConnectionState* connection_ = nullptr;
  std::int64_t command_id_ = 0;
  std::string name_;
  std::optional<std::int64_t> revision_;
};

// A read transaction (see Project::read_snapshot); ends on destruction.
class Project::ReadSnapshot {
 public:
  ReadSnapshot(ReadSnapshot&& other) noexcept
      : db_(std::exchange(other.db_, nullptr)),
        connection_(std::exchange(other.connection_, nullptr)) {}
  ReadSnapshot& operator=(ReadSnapshot&&) = delete;
  ~ReadSnapshot();

 private:
  friend class Project;
  // Marks the connection as holding a snapshot (none inside a Batch).
  ReadSnapshot(sqlite3* db, ConnectionState* connection);
  sqlite3* db_ = nullptr;
  ConnectionState* connection_ = nullptr;
};

// Several commands as one transaction (see Project::begin_batch). Rolled
// back on destruction unless committed. Must not outlive its Project.
class Project::Batch {
 public:
  Batch(Batch&& other) noexcept
      : db_(std::exchange(other.db_, nullptr)),
        file_(std::move(other.file_)),
        connection_(other.connection_) {}
  Batch& operator=(Batch&&) = delete;
  ~Batch();

  // Makes everything written inside durable at once. Asserts no Edit is
  // open. Throws core::RuntimeFailure when SQLite cannot commit (I/O error,
  // disk full) or already rolled the batch back after such an error;
  // nothing is then stored.
  void commit();

 private:
  friend class Project;
  Batch(sqlite3* db, std::string file, ConnectionState* connection)
      : db_(db), file_(std::move(file)), connection_(connection) {}
  void roll_back() noexcept;

  sqlite3* db_ = nullptr;
  std::string file_;
  ConnectionState* connection_ = nullptr;
};

// A project being built under a temporary name (Project::create_draft).
// Its path() is the name it will have, and messages name that. Removed on
// destruction unless published.
class Project::Draft {
 public:
  Draft(Draft&&) noexcept = default;
  Draft& operator=(Draft&&) = delete;
  ~Draft();

  Project& project() { return *project_; }

  // Closes the draft and moves it to its name unless a file of that name
  // appeared meanwhile (another process created it): then the draft is
  // removed and false returned. Throws core::RuntimeFailure when the file
  // system refuses the move; the draft is removed.
  bool publish();

 private:
  friend class Project;
  Draft(Project project, std::filesystem::path temporary)
      : project_(std::make_unique<Project>(std::move(project))), temporary_(std::move(temporary)) {}
  std::unique_ptr<Project> project_;
  std::filesystem::path temporary_;
};

}  // namespace scanbench::store
