// The project file (.sbproj): one SQLite database holding the scans (metadata,
// pose, channels as zstd blobs) and, in later schema versions, geometry,
// objects, edits and the command journal.
//
// Durability: the database runs in write-ahead-log mode with synchronous=FULL,
// so every committed Transaction survives a crash or power loss, and a process
// killed mid-transaction leaves the file exactly as it was at the last commit.
// Every user-level change is one Transaction.
//
// Threading: a Project is one SQLite connection opened without SQLite's own
// mutexes (SQLITE_OPEN_NOMUTEX); use it from one thread at a time. Several
// processes may open the same file; writers wait for each other for up to
// kBusyTimeoutMs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "acquisition/scan.hpp"
#include "acquisition/scan_geometry.hpp"
#include "acquisition/scan_summary.hpp"

struct sqlite3;

namespace scanbench::modeling {

// PRAGMA application_id of every scanbench project: "SBNC" in ASCII. Files
// with another id are other applications' databases and are never touched.
inline constexpr std::uint32_t kProjectApplicationId = 0x53424E43;

// PRAGMA user_version written by this build. Older projects are migrated on
// open; newer ones are refused.
// 2: scan_geometry; 3: registration_runs, merge_masks.
inline constexpr int kProjectSchemaVersion = 3;

// How long a write waits for another process's write to finish [ms].
inline constexpr int kBusyTimeoutMs = 5000;

struct StoredScanSummary {
  std::int64_t id = 0;  // the project's id of the scan, stable for the project's life
  acquisition::ScanSummary summary;
};

// Deletes a project file with its SQLite side files (-journal, -wal, -shm).
// For a project the caller itself created and must not leave behind; errors
// are ignored (the files may not exist).
void remove_project_files(const std::filesystem::path& file);

class Project {
 public:
  class Transaction;

  // Opens an existing project for reading and writing. Never creates or
  // recreates the file. Throws core::InputError, leaving the file
  // untouched, when it is missing, a directory, empty, not an SQLite
  // database, another application's database, a project of a newer schema
  // version, damaged, or locked by another writer for longer than
  // kBusyTimeoutMs. Older schema versions are migrated in one transaction.
  static Project open(const std::filesystem::path& file);

  // Creates a new, empty project. Throws core::InputError when the
  // file already exists (it is never overwritten) or cannot be created; a
  // half-created file is removed again.
  static Project create(const std::filesystem::path& file);

  // open() when `file` exists, else create().
  static Project open_or_create(const std::filesystem::path& file);

  Project(Project&&) noexcept = default;
  Project& operator=(Project&&) noexcept = default;
  ~Project();  // closes the connection; an open Transaction must be gone by then

  // The file as passed to open/create.
  const std::filesystem::path& path() const { return file_; }

  // PRAGMA user_version of the open file; kProjectSchemaVersion after open().
  int schema_version() const;

  // Every scan's summary (sizes, channel presence, pose, world bounds,
  // scanner metadata) ordered by id, without reading channel data. Throws
  // core::InputError when the file is damaged.
  std::vector<StoredScanSummary> scans() const;

  // The scan stored under `id`, bit-identical to what insert_scan stored.
  // Throws core::InputError "no scan with id N" when there is none,
  // and names the scan and channel when its data is damaged.
  acquisition::Scan load_scan(std::int64_t id) const;

  // Starts a write transaction (BEGIN IMMEDIATE: takes the write lock now, so
  // a commit never fails for a concurrent writer). Asserts that no
  // transaction is open. Throws core::InputError when another process
  // keeps the write lock for longer than kBusyTimeoutMs.
  Transaction begin();

  // Stores `scan` (metadata, pose, summary, channels as zstd blobs) and
  // returns its new id. Asserts that a Transaction is open and that the scan
  // passes acquisition::check_consistency. Throws core::InputError
  // when SQLite fails (disk full, blob larger than SQLite's 1 GB limit); the
  // caller's Transaction then rolls everything back.
  std::int64_t insert_scan(const acquisition::Scan& scan);

  // Stores (replacing any earlier) the geometry of scan `id`, with the
  // settings that produced it as JSON text. Asserts a Transaction is open and
  // the arrays match the scan's pixel count; throws core::InputError
  // when there is no such scan or SQLite fails.
  void store_geometry(std::int64_t id, const acquisition::GeometryResult& geometry,
                      const std::string& settings_json);

  // The stored geometry of scan `id`, or none when `scanbench geometry` has
  // not run on it. Throws core::InputError naming the scan when the
  // stored data is damaged.
  std::optional<acquisition::ScanGeometry> load_geometry(std::int64_t id) const;

  // Moves scan `id` to scan.T_world_scan: stores the pose, the scanner
  // position (the pose's origin) and the world bounds of `scan`, which must
  // be the stored scan with only its pose changed (asserted on size). Asserts
  // a Transaction is open; throws core::InputError when there is no
  // such scan or SQLite fails.
  void update_pose(std::int64_t id, const acquisition::Scan& scan);

  // Appends a registration run: its settings and report as JSON text.
  // Asserts a Transaction is open; throws core::InputError when SQLite fails.
  void store_registration(const std::string& settings_json, const std::string& report_json);

  // The report of the latest registration run, or none.
  std::optional<std::string> latest_registration_report() const;

  // Stores (replacing any earlier) the merge keep mask of scan `id`: one
  // byte per pixel, 1 = in the merged model. Asserts a Transaction is open
  // and the mask matches the scan's pixel count; throws
  // core::InputError when there is no such scan or SQLite fails.
  void store_keep_mask(std::int64_t id, std::span<const std::uint8_t> keep,
                       const std::string& settings_json);

  // The keep mask of scan `id`, or none when `scanbench merge` has not run
  // since its pose last changed. Throws core::InputError when damaged.
  std::optional<std::vector<std::uint8_t>> load_keep_mask(std::int64_t id) const;

  // Deletes every keep mask (poses changed: the masks are stale). Asserts a
  // Transaction is open.
  void clear_keep_masks();

 private:
  struct CloseConnection {
    void operator()(sqlite3* db) const noexcept;
  };
  using Connection = std::unique_ptr<sqlite3, CloseConnection>;

  Project(std::filesystem::path file, Connection db);
  sqlite3* db() const;
  std::string file_name() const { return file_.string(); }
  // rows × columns of scan `id`; throws core::InputError when there is none.
  std::size_t stored_pixel_count(std::int64_t id) const;

  std::filesystem::path file_;
  Connection db_;
};

// One write transaction: everything done through the Project between begin()
// and commit() lands in the file together or not at all. Rolled back on
// destruction unless committed. Must not outlive its Project.
class Project::Transaction {
 public:
  Transaction(Transaction&& other) noexcept;
  Transaction& operator=(Transaction&& other) noexcept;
  ~Transaction();

  // Makes the changes durable. Asserts the transaction is still open. Throws
  // core::InputError when SQLite cannot commit (I/O error, disk full);
  // the changes are then rolled back when the Transaction is destroyed.
  void commit();

  // False once committed or moved from.
  bool active() const { return db_ != nullptr; }

 private:
  friend class Project;
  Transaction(sqlite3* db, std::string file) : db_(db), file_(std::move(file)) {}
  void roll_back() noexcept;

  sqlite3* db_ = nullptr;
  std::string file_;
};

}  // namespace scanbench::modeling
