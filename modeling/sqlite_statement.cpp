#include "modeling/sqlite_statement.hpp"

#include <cassert>

#include "core/errors.hpp"

namespace scanbench::modeling::sqlite {

namespace {

bool is_damage(int code) {
  const int primary = code & 0xff;
  return primary == SQLITE_CORRUPT || primary == SQLITE_NOTADB;
}

}  // namespace

void throw_error(sqlite3* db, int code, const std::string& file, const std::string& action) {
  std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
  if (is_damage(code)) message = "project file is damaged (" + message + ")";
  core::FilePosition position;
  position.detail = action;
  throw core::InputError(file, position, message);
}

void execute(sqlite3* db, const char* sql, const std::string& file) {
  const int code = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
  if (code != SQLITE_OK) throw_error(db, code, file, std::string("running \"") + sql + "\"");
}

Statement::Statement(sqlite3* db, const char* sql, std::string file)
    : db_(db), file_(std::move(file)), sql_(sql) {
  assert(db != nullptr && "statement on a closed project connection");
  const int code = sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr);
  if (code != SQLITE_OK) throw_error(db, code, file_, std::string("preparing \"") + sql + "\"");
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

bool Statement::step() {
  const int code = sqlite3_step(statement_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  throw_error(db_, code, file_, std::string("running \"") + sql_ + "\"");
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

}  // namespace scanbench::modeling::sqlite
