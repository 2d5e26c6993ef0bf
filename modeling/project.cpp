#include "modeling/project.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <cstring>
#include <utility>

#include "core/errors.hpp"
#include "modeling/project_schema.hpp"
#include "modeling/sqlite_statement.hpp"

namespace scanbench::modeling {

namespace {

// Read-write without SQLITE_OPEN_CREATE: a project deleted between our header
// check and this call must not be recreated empty. NOMUTEX: one connection
// per Project, used from one thread at a time (see project.hpp).
sqlite3* connect(const std::filesystem::path& file) {
  sqlite3* db = nullptr;
  const int code =
      sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (code != SQLITE_OK) {
    const std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
    sqlite3_close(db);
    core::FilePosition position;
    position.detail = "opening the project";
    throw core::RuntimeFailure(file.string(), position, message);
  }
  sqlite3_extended_result_codes(db, 1);
  return db;
}

// O_EXCL makes "refuse an existing file" atomic: no other process can slip a
// file in between a check and SQLite's open.
void create_exclusively(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int error = errno;
    if (error == EEXIST) {
      throw core::InputError(file.string(), {},
                             "file already exists; a new project never overwrites a file");
    }
    const std::string problem = std::string("cannot create the project: ") + std::strerror(error);
    // A missing folder or a bad name is the user's; a full, read-only or
    // failing disk is the machine's.
    if (error == ENOENT || error == ENOTDIR || error == EISDIR || error == ENAMETOOLONG) {
      throw core::InputError(file.string(), {}, problem);
    }
    throw core::RuntimeFailure(file.string(), {}, problem);
  }
  ::close(fd);
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
    : file_(std::move(file)), db_(std::move(db)) {}

Project::~Project() = default;

sqlite3* Project::db() const {
  assert(db_ && "use of a moved-from Project");
  return db_.get();
}

Project Project::open(const std::filesystem::path& file) {
  schema::check_file_header(file);
  Project project(file, Connection(connect(file)));
  schema::configure_connection(project.db(), project.file_name());
  schema::check_and_migrate(project.db(), project.file_name());
  return project;
}

Project Project::create(const std::filesystem::path& file) {
  create_exclusively(file);
  try {
    Project project(file, Connection(connect(file)));
    schema::configure_connection(project.db(), project.file_name());
    schema::create_schema(project.db(), project.file_name());
    return project;
  } catch (...) {
    remove_project_files(file);
    throw;
  }
}

Project Project::open_or_create(const std::filesystem::path& file) {
  std::error_code error;
  return std::filesystem::exists(file, error) ? open(file) : create(file);
}

int Project::schema_version() const {
  return schema::read_schema_version(db(), file_name());
}

void Project::check_edit([[maybe_unused]] const Edit& edit) const {
  assert(edit.active() && edit.db_ == db() && "writes need an open Edit of this project");
}

Project::Edit::Edit(Edit&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)),
      file_(std::move(other.file_)),
      command_id_(other.command_id_),
      kind_(other.kind_) {}

Project::Edit& Project::Edit::operator=(Edit&& other) noexcept {
  if (this != &other) {
    roll_back();
    db_ = std::exchange(other.db_, nullptr);
    file_ = std::move(other.file_);
    command_id_ = other.command_id_;
    kind_ = other.kind_;
  }
  return *this;
}

Project::Edit::~Edit() {
  roll_back();
}

void Project::Edit::roll_back() noexcept {
  // SQLite may already have rolled back by itself after an I/O error or a
  // full disk; ROLLBACK would then fail, so only issue it when still open.
  if (db_ != nullptr && sqlite3_get_autocommit(db_) == 0) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  db_ = nullptr;
}

}  // namespace scanbench::modeling
