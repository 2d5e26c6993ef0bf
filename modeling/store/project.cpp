#include "modeling/store/project.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <stdio.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <cstring>
#include <random>
#include <utility>

#include "core/errors.hpp"
#include "modeling/store/object_tree_cache.hpp"
#include "modeling/store/schema.hpp"
#include "modeling/store/sqlite_statement.hpp"

namespace scanbench::store {

namespace {

// Read-write without SQLITE_OPEN_CREATE: a project deleted between our header
// check and this call must not be recreated empty. NOMUTEX: one connection
// per Project, used from one thread at a time (see project.hpp).
sqlite3* connect(const std::filesystem::path& file, int flags = SQLITE_OPEN_READWRITE) {
  return sqlite::open_connection(file.string(), flags, "opening the project");
}

// "file:/path?immutable=1": SQLite then reads without any lock or
// shared-memory file, as a write-protected medium needs.
std::string immutable_uri(const std::filesystem::path& file) {
  std::string uri = "file:";
  for (const char c : std::filesystem::absolute(file).string()) {
    if (c == '%' || c == '?' || c == '#') {
      static constexpr char kHex[] = "0123456789ABCDEF";
      uri += '%';
      uri += kHex[(static_cast<unsigned char>(c) >> 4) & 15];
      uri += kHex[static_cast<unsigned char>(c) & 15];
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

// True when this process may write the file and create files beside it
// (SQLite's -wal and -shm).
bool writable(const std::filesystem::path& file) {
  const std::filesystem::path folder =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  return ::access(file.c_str(), W_OK) == 0 && ::access(folder.c_str(), W_OK) == 0;
}

// Moves the finished `temporary` to `file` unless `file` exists. Returns
// false when it exists. Where the file system can rename without replacing,
// that is one step; elsewhere a hard link does the same.
bool place_without_replacing(const std::filesystem::path& temporary,
                             const std::filesystem::path& file) {
  const auto refuse = [&](int code) {
    throw core::RuntimeFailure(file.string(), {},
                               std::string("cannot create the project: ") + std::strerror(code));
  };
  if (::renameat2(AT_FDCWD, temporary.c_str(), AT_FDCWD, file.c_str(), RENAME_NOREPLACE) == 0) {
    return true;
  }
  if (errno == EEXIST) return false;
  if (errno != EINVAL && errno != ENOSYS) refuse(errno);
  if (::link(temporary.c_str(), file.c_str()) == 0) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return true;
  }
  if (errno == EEXIST) return false;
  if (errno != EPERM && errno != EOPNOTSUPP) refuse(errno);
  // A file system with neither (FAT, some FUSE mounts): claim the name with
  // an empty file first, then replace that one. Another process may see it
  // empty for a moment and refuse it as not a project; none overwrites one.
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    if (errno == EEXIST) return false;
    refuse(errno);
  }
  ::close(fd);
  if (::rename(temporary.c_str(), file.c_str()) != 0) {
    const int code = errno;
    ::unlink(file.c_str());
    refuse(code);
  }
  return true;
}

void refuse_existing(const std::filesystem::path& file) {
  throw core::InputError(file.string(), {},
                         "file already exists; a new project never overwrites a file");
}

// The folder must be there: a missing one is the user's mistake.
void check_folder(const std::filesystem::path& file) {
  const std::filesystem::path folder =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw core::InputError(file.string(), {}, "cannot create the project: no such folder");
  }
}

// Builds a new, empty project at a temporary name beside `file` and closes
// it (its write-ahead log checkpointed away). Returns the temporary path.
std::filesystem::path build_empty_project(const std::filesystem::path& file) {
  // Unique across processes and hosts sharing the folder.
  const std::filesystem::path temporary = file.string() + ".creating-" +
                                          std::to_string(::getpid()) + "-" +
                                          std::to_string(std::random_device{}());
  try {
    sqlite3* raw = connect(temporary, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> db(raw, &sqlite3_close);
    schema::configure_connection(raw, file.string());
    schema::create_schema(raw, file.string());
  } catch (...) {
    remove_project_files(temporary);
    throw;
  }
  return temporary;
}

}  // namespace

void remove_project_files(const std::filesystem::path& file) {
  std::error_code ignored;
  for (const char* suffix : {"", "-journal", "-wal", "-shm"}) {
    std::filesystem::remove(file.string() + suffix, ignored);
  }
}

void Project::CloseConnection::operator()(sqlite3* db) const noexcept {
  // Fails only with statements left unfinalized, which RAII rules out.
  [[maybe_unused]] const int code = sqlite3_close(db);
  assert(code == SQLITE_OK && "project connection closed with live statements");
}

Project::Project(std::filesystem::path file, Connection db)
    : file_(std::move(file)),
      db_(std::move(db)),
      connection_(std::make_unique<ConnectionState>()) {}

Project::Project(Project&&) noexcept = default;
Project& Project::operator=(Project&&) noexcept = default;
Project::~Project() = default;

sqlite3* Project::db() const {
  assert(db_ && "use of a moved-from Project");
  return db_.get();
}

Project Project::open(const std::filesystem::path& file) {
  schema::check_file_kind(file);
  if (!writable(file)) {
    throw core::RuntimeFailure(file.string(), {},
                               "cannot write the project: it, or its folder, is read-only here "
                               "(info, export and history still read it)");
  }
  Project project(file, Connection(connect(file)));
  schema::check_file_header(project.db(), file);
  schema::configure_connection(project.db(), project.file_name());
  schema::check_and_migrate(project.db(), project.file_name());
  return project;
}

Project::Draft Project::create_draft(const std::filesystem::path& file) {
  std::error_code error;
  if (std::filesystem::exists(std::filesystem::symlink_status(file, error))) refuse_existing(file);
  check_folder(file);
  const std::filesystem::path temporary = build_empty_project(file);
  try {
    Project project(file, Connection(connect(temporary)));
    schema::configure_connection(project.db(), project.file_name());
    return Draft(std::move(project), temporary);
  } catch (...) {
    remove_project_files(temporary);
    throw;
  }
}

Project::Draft::~Draft() {
  if (!temporary_.empty()) {
    project_.reset();
    remove_project_files(temporary_);
  }
}

bool Project::Draft::publish() {
  assert(project_ && "publish of a published or moved-from draft");
  const std::filesystem::path file = project_->path();
  project_.reset();  // closed: its write-ahead log is checkpointed into the file
  bool placed = false;
  try {
    placed = place_without_replacing(temporary_, file);
  } catch (...) {
    remove_project_files(temporary_);
    temporary_.clear();
    throw;
  }
  if (!placed) remove_project_files(temporary_);
  temporary_.clear();
  return placed;
}

Project Project::create(const std::filesystem::path& file) {
  Draft draft = create_draft(file);
  if (!draft.publish()) refuse_existing(file);
  return open(file);
}

Project Project::open_or_create(const std::filesystem::path& file, bool* created) {
  std::error_code error;
  const bool exists = std::filesystem::exists(std::filesystem::symlink_status(file, error));
  const bool placed = !exists && create_draft(file).publish();
  if (created != nullptr) *created = placed;
  return open(file);
}

Project Project::open_for_reading(const std::filesystem::path& file) {
  return writable(file) ? open(file) : open_read_only(file);
}

Project Project::open_read_only(const std::filesystem::path& file) {
  schema::check_file_kind(file);
  // Read-only: SQLite still needs the shared-memory file of the write-ahead
  // log. Where it cannot make one (a write-protected medium) and the log is
  // empty, the file holds every change and is read as immutable; a log with
  // changes in it cannot be read safely without that file.
  Connection db(connect(file, SQLITE_OPEN_READONLY));
  schema::check_file_header(db.get(), file);
  const int probe = sqlite3_exec(db.get(), "PRAGMA user_version", nullptr, nullptr, nullptr);
  if ((probe & 0xff) == SQLITE_CANTOPEN || (probe & 0xff) == SQLITE_READONLY) {
    std::error_code error;
    const auto log_size = std::filesystem::file_size(file.string() + "-wal", error);
    if (!error && log_size > 0) {
      throw core::RuntimeFailure(file.string(), {},
                                 "cannot read the project here: its write-ahead log holds "
                                 "changes and the folder is read-only; copy the project, with "
                                 "its -wal file, to writable storage");
    }
    db = Connection(connect(immutable_uri(file), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI));
  }
  schema::check_readable(db.get(), file.string());
  return Project(file, std::move(db));
}

int Project::schema_version() const {
  return schema::read_schema_version(db(), file_name());
}

void Project::check_edit([[maybe_unused]] const Edit& edit) const {
  assert(edit.active() && edit.db_ == db() && "writes need an open Edit of this project");
}

Project::Edit::Edit(sqlite3* db, std::string file, std::int64_t command_id, Kind kind,
                    ConnectionState* connection)
    : file_(std::move(file)),
      command_id_(command_id),
      kind_(kind),
      nested_(connection->batch),
      connection_(connection) {
  assert(!connection->edit && !connection->snapshot &&
         "an Edit inside another Edit or a ReadSnapshot");
  // Outside a transaction a savepoint would begin one of its own, which
  // its release would commit: a batch that SQLite rolled back after a write
  // error must stop here.
  if (nested_) require_open_batch(db, *connection, file_);
  sqlite::execute(db, nested_ ? "SAVEPOINT edit" : "BEGIN IMMEDIATE", file_);
  db_ = db;
  connection->edit = true;
}

Project::Edit::Edit(Edit&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)),
      file_(std::move(other.file_)),
      command_id_(other.command_id_),
      kind_(other.kind_),
      nested_(other.nested_),
      writes_(other.writes_),
      connection_(other.connection_) {}

Project::Edit& Project::Edit::operator=(Edit&& other) noexcept {
  if (this != &other) {
    roll_back();
    db_ = std::exchange(other.db_, nullptr);
    file_ = std::move(other.file_);
    command_id_ = other.command_id_;
    kind_ = other.kind_;
    nested_ = other.nested_;
    writes_ = other.writes_;
    connection_ = other.connection_;
  }
  return *this;
}

Project::Edit::~Edit() {
  roll_back();
}

void Project::Edit::roll_back() noexcept {
  if (db_ == nullptr) return;
  // SQLite may already have rolled back by itself after an I/O error or a
  // full disk; ROLLBACK would then fail, so only issue it when still open.
  if (sqlite3_get_autocommit(db_) == 0) {
    const int code = sqlite3_exec(db_, nested_ ? "ROLLBACK TO edit; RELEASE edit" : "ROLLBACK",
                                  nullptr, nullptr, nullptr);
    // What the refused command wrote may still be in the batch: it must not commit.
    if (nested_ && code != SQLITE_OK) connection_->batch_failed = true;
  }
  db_ = nullptr;
  connection_->edit = false;
  connection_->tree.drop_writes();
}

Project::ReadSnapshot::ReadSnapshot(sqlite3* db, ConnectionState* connection)
    : db_(db), connection_(connection) {
  if (connection_ != nullptr) connection_->snapshot = true;
}

}  // namespace scanbench::store
