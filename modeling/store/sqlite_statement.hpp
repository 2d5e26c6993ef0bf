// Thin RAII layer over the SQLite C API for the project code in modeling/.
// Internal to scanbench_modeling (which links SQLite privately): nothing
// outside modeling/ should include this header.
//
// Every SQLite failure becomes an exception naming the project file, the
// action that failed and SQLite's message: core::InputError when the file is
// at fault (damaged, not a database, data refused by the schema),
// core::RuntimeFailure when the machine is (disk full, I/O error, no
// permission, locked by another process, out of memory).
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace scanbench::store::sqlite {

// Throws InputError or RuntimeFailure (see above) with detail = action and
// problem = SQLite's message for `code`. A damaged database (SQLITE_CORRUPT,
// SQLITE_NOTADB) is called out as such. `db` may be null (the message then
// comes from `code` alone).
[[noreturn]] void throw_error(sqlite3* db, int code, const std::string& file,
                              const std::string& action);

// Opens a connection to `file` with `flags` (SQLITE_OPEN_*; NOMUTEX added:
// a connection serves one thread at a time) and extended result codes.
// Throws core::RuntimeFailure naming the file, with detail `action`, when
// it cannot.
sqlite3* open_connection(const std::string& file, int flags, const std::string& action);

// Runs SQL that returns no rows (may hold several statements); throws as
// throw_error on failure.
void execute(sqlite3* db, const char* sql, const std::string& file);

// As execute, binding `value` to parameter ?1 of every statement that has one.
void execute_with_int(sqlite3* db, const char* sql, std::int64_t value, const std::string& file);

// One prepared statement, finalized on destruction. Parameter and column
// indices follow SQLite: parameters from 1, columns from 0. Not copyable or
// movable: statements live on the stack of the function that runs them.
class Statement {
 public:
  // Throws as throw_error when `sql` does not compile against the schema
  // (for instance because the project file is damaged).
  Statement(sqlite3* db, const char* sql, std::string file);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind_int(int index, std::int64_t value);
  Statement& bind_double(int index, double value);
  Statement& bind_optional_double(int index, std::optional<double> value);  // NULL when empty
  Statement& bind_null(int index);
  Statement& bind_text(int index, std::string_view value);  // copied by SQLite
  // Not copied: `value` must outlive the next step().
  Statement& bind_blob(int index, std::span<const std::uint8_t> value);
  // A blob of `bytes` zero bytes, to be filled in place (sqlite3_blob_write).
  Statement& bind_zeroblob(int index, std::uint64_t bytes);

  // Advances; true when a row is available, false when the statement is done.
  // Throws as throw_error on failure.
  bool step();
  // Steps a statement that must not return rows (INSERT, UPDATE, ...).
  void run();

  bool is_null(int column) const;
  std::int64_t column_int(int column) const;
  double column_double(int column) const;
  std::string column_text(int column) const;
  // Valid until the next step() or the statement's destruction.
  std::span<const std::uint8_t> column_blob(int column) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* statement_ = nullptr;
  std::string file_;
  const char* sql_;
};

}  // namespace scanbench::store::sqlite
