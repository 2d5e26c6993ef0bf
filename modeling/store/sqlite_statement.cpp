#include "modeling/store/sqlite_statement.hpp"

#include <cassert>
#include <memory>
#include <string_view>

#include "core/errors.hpp"

namespace scanbench::store::sqlite {

namespace {

bool is_damage(int code) {
  const int primary = code & 0xff;
  return primary == SQLITE_CORRUPT || primary == SQLITE_NOTADB;
}

// Failures of the machine or the environment rather than of the file.
bool is_runtime_failure(int code) {
  switch (code & 0xff) {
    case SQLITE_FULL:
    case SQLITE_IOERR:
    case SQLITE_NOMEM:
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
    case SQLITE_READONLY:
    case SQLITE_CANTOPEN:
    case SQLITE_PERM:
    case SQLITE_NOLFS:
    case SQLITE_INTERRUPT:
      return true;
    default:
      return false;
  }
}

// "INSERT INTO scan_layers": the first words of a statement, to name what
// failed without printing it whole.
std::string statement_summary(std::string_view sql) {
  const std::size_t start = sql.find_first_not_of(" \n\t");
  if (start == std::string_view::npos) return "SQL";
  sql.remove_prefix(start);
  std::string words;
  int count = 0;
  for (std::size_t i = 0; i < sql.size() && count < 3; ++i) {
    const char c = sql[i];
    const bool space = c == ' ' || c == '\n' || c == '\t' || c == '(';
    if (space) {
      if (!words.empty() && words.back() != ' ') {
        words += ' ';
        ++count;
      }
    } else {
      words += c;
    }
  }
  while (!words.empty() && words.back() == ' ') words.pop_back();
  return words;
}

}  // namespace

void throw_error(sqlite3* db, int code, const std::string& file, const std::string& action) {
  std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
  if (is_damage(code)) message = "project file is damaged (" + message + ")";
  const int primary = code & 0xff;
  if (primary == SQLITE_FULL || primary == SQLITE_IOERR) {
    // Say what it means for the user; SQLite's words stay in brackets.
    throw core::RuntimeFailure(file, {}, "the disk is full or failing (" + message + ")");
  }
  if (primary == SQLITE_READONLY) {
    throw core::RuntimeFailure(file, {}, "cannot write the project: it is read-only here");
  }
  if (primary == SQLITE_BUSY || primary == SQLITE_LOCKED) {
    throw core::RuntimeFailure(
        file, {}, "another scanbench keeps the project locked; try again when it has finished");
  }
  core::FilePosition position;
  position.detail = action;
  if (is_runtime_failure(code)) throw core::RuntimeFailure(file, position, message);
  throw core::InputError(file, position, message);
}

sqlite3* open_connection(const std::string& file, int flags, const std::string& action) {
  sqlite3* db = nullptr;
  const int code = sqlite3_open_v2(file.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr);
  if (code != SQLITE_OK) {
    const std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
    sqlite3_close(db);
    core::FilePosition position;
    position.detail = action;
    throw core::RuntimeFailure(file, position, message);
  }
  sqlite3_extended_result_codes(db, 1);
  return db;
}

void execute(sqlite3* db, const char* sql, const std::string& file) {
  const int code = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
  if (code != SQLITE_OK) throw_error(db, code, file, "running " + statement_summary(sql));
}

void execute_with_int(sqlite3* db, const char* sql, std::int64_t value, const std::string& file) {
  const char* rest = sql;
  while (rest != nullptr && *rest != '\0') {
    sqlite3_stmt* raw = nullptr;
    const char* next = nullptr;
    int code = sqlite3_prepare_v2(db, rest, -1, &raw, &next);
    const std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)> statement(raw,
                                                                               &sqlite3_finalize);
    if (code != SQLITE_OK) throw_error(db, code, file, "preparing " + statement_summary(rest));
    if (!statement) break;  // only whitespace or comments left
    if (sqlite3_bind_parameter_count(raw) > 0) sqlite3_bind_int64(raw, 1, value);
    while ((code = sqlite3_step(raw)) == SQLITE_ROW) {
    }
    if (code != SQLITE_DONE) throw_error(db, code, file, "running " + statement_summary(rest));
    rest = next;
  }
}

Statement::Statement(sqlite3* db, const char* sql, std::string file)
    : db_(db), file_(std::move(file)), sql_(sql) {
  assert(db != nullptr && "statement on a closed project connection");
  const int code = sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr);
  if (code != SQLITE_OK) throw_error(db, code, file_, "preparing " + statement_summary(sql));
}

Statement::~Statement() {
  sqlite3_finalize(statement_);
}

// A failed bind is always a programmer error (index out of range, statement
// already running), never bad data.
Statement& Statement::bind_int(int index, std::int64_t value) {
  [[maybe_unused]] const int code = sqlite3_bind_int64(statement_, index, value);
  assert(code == SQLITE_OK && "sqlite bind failed");
  return *this;
}

Statement& Statement::bind_double(int index, double value) {
  [[maybe_unused]] const int code = sqlite3_bind_double(statement_, index, value);
  assert(code == SQLITE_OK && "sqlite bind failed");
  return *this;
}

Statement& Statement::bind_null(int index) {
  [[maybe_unused]] const int code = sqlite3_bind_null(statement_, index);
  assert(code == SQLITE_OK && "sqlite bind failed");
  return *this;
}

Statement& Statement::bind_optional_double(int index, std::optional<double> value) {
  if (value) return bind_double(index, *value);
  [[maybe_unused]] const int code = sqlite3_bind_null(statement_, index);
  assert(code == SQLITE_OK && "sqlite bind failed");
  return *this;
}

Statement& Statement::bind_text(int index, std::string_view value) {
  const int code = sqlite3_bind_text64(statement_, index, value.data(), value.size(),
                                       SQLITE_TRANSIENT, SQLITE_UTF8);
  if (code != SQLITE_OK) throw_error(db_, code, file_, "binding a text");
  return *this;
}

Statement& Statement::bind_blob(int index, std::span<const std::uint8_t> value) {
  // A null pointer would bind NULL instead of an empty blob.
  static constexpr std::uint8_t kEmpty = 0;
  const void* data = value.empty() ? &kEmpty : value.data();
  const int code = sqlite3_bind_blob64(statement_, index, data, value.size(), SQLITE_STATIC);
  // SQLITE_TOOBIG is bad data (a channel over SQLite's 1 GB blob limit), not a bug.
  if (code != SQLITE_OK) throw_error(db_, code, file_, "binding a blob");
  return *this;
}

Statement& Statement::bind_zeroblob(int index, std::uint64_t bytes) {
  const int code = sqlite3_bind_zeroblob64(statement_, index, bytes);
  if (code != SQLITE_OK) throw_error(db_, code, file_, "binding a blob");
  return *this;
}

bool Statement::step() {
  const int code = sqlite3_step(statement_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  throw_error(db_, code, file_, "running " + statement_summary(sql_));
}

void Statement::run() {
  [[maybe_unused]] const bool has_row = step();
  assert(!has_row && "statement run for its effect returned a row");
}

bool Statement::is_null(int column) const {
  return sqlite3_column_type(statement_, column) == SQLITE_NULL;
}

std::int64_t Statement::column_int(int column) const {
  return sqlite3_column_int64(statement_, column);
}

double Statement::column_double(int column) const {
  return sqlite3_column_double(statement_, column);
}

std::string Statement::column_text(int column) const {
  const auto* text = sqlite3_column_text(statement_, column);
  const int bytes = sqlite3_column_bytes(statement_, column);
  if (text == nullptr) return {};
  return std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(bytes));
}

std::span<const std::uint8_t> Statement::column_blob(int column) const {
  const void* data = sqlite3_column_blob(statement_, column);
  const int bytes = sqlite3_column_bytes(statement_, column);
  if (data == nullptr) return {};
  return {static_cast<const std::uint8_t*>(data), static_cast<std::size_t>(bytes)};
}

}  // namespace scanbench::store::sqlite
