// The project file (.sbproj): one SQLite database holding the scans, their
// poses and per-pixel layers, and the journal of every command that changed
// them.
//
// Commands and undo: every change is a command (import, geometry, register,
// merge, …) made through a Project::Edit, which records the command in the
// journal and commits it with its effect in one transaction. Nothing is
// overwritten: every row a command writes (a scan, a pose, a layer version)
// carries the command's id, and what the project holds is, for each scan,
// pose and layer, the row of the newest done command (newest by journal
// order, `seq`). Undo marks the newest done command undone; redo marks the
// oldest undone command done again; a new command discards the undone ones
// (and, by cascade, their rows). Undo and redo therefore work across
// processes and restore the earlier state exactly.
//
// Long commands (an import of many large scans) write in parts, each its
// own short transaction, under a command in state "pending" whose rows no
// reader sees; finishing it makes it done in one last transaction. A
// pending command whose process died is removed by the next writer.
// (docs/CONTRIBUTING.md shows how a stage uses this.)
//
// Durability: write-ahead-log mode with synchronous=FULL, so every committed
// Edit survives a crash or power loss, and a process killed mid-edit leaves
// the file exactly as it was at the last commit.
//
// Threading: a Project is one SQLite connection opened without SQLite's own
// mutexes (SQLITE_OPEN_NOMUTEX); use it from one thread at a time. Several
// processes may open the same file; writers wait for each other for up to
// kBusyTimeoutMs.
#pragma once

#include <Eigen/Geometry>
#include <cassert>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "acquisition/scan.hpp"
#include "acquisition/scan_source.hpp"
#include "acquisition/scan_summary.hpp"
#include "core/memory.hpp"
#include "core/project_file.hpp"
#include "modeling/store/color_edit.hpp"
#include "modeling/store/command_footprint.hpp"
#include "modeling/store/layer_rows.hpp"
#include "modeling/store/layer_store.hpp"

struct sqlite3;

namespace scanbench::store {

// PRAGMA application_id of every scanbench project: "SBNC" in ASCII. Files
// with another id are other applications' databases and are never touched.
inline constexpr std::uint32_t kProjectApplicationId = core::kProjectApplicationId;

// PRAGMA user_version written by this build. Older projects are migrated on
// open; newer ones are refused.
// 2: scan_geometry; 3: registration_runs, merge_masks; 4: the command journal,
// versioned poses and the per-scan layer store; 5: the object tree; 6: colour
// edits of objects and colour corrections of scans; 7: scan sources and images;
// 8: indexes of the journal's undone and pending commands; 9: scattered
// scans; 10: a layer's frame in a column of its own, written in place.
inline constexpr int kProjectSchemaVersion = 10;

// How long a write waits for another process's write to finish [ms].
inline constexpr int kBusyTimeoutMs = 5000;

enum class NodeKind { kGroup, kObject };

// The longest name a user may give a node [bytes of UTF-8]. Names hold no
// control characters (the commands refuse them: modeling/node_tree.hpp).
inline constexpr std::size_t kMaxNodeNameBytes = 256;

// A node of the object tree (site → building → wall …). Objects own pixels
// of scans (their "membership" layers); groups hold other nodes. The cached
// figures describe the points the node owns, its descendants' included.
struct ObjectNode {
  std::int64_t id = 0;  // > 0; stable for the node's life
  std::string name;     // UTF-8, for people; not unique
  NodeKind kind = NodeKind::kObject;
  std::optional<std::int64_t> parent;  // none: a root of the tree
  bool hidden = false;
  std::int64_t points = 0;
  std::optional<double> mean_footprint_m;         // [m]; none without points
  std::optional<Eigen::AlignedBox3d> bbox_world;  // [m]; none without points
  ColorEdit color;  // what the node itself sets (color_edit.hpp); the rest it inherits
};

// An image stored with the scans (E57 images2D).
struct StoredImage {
  std::int64_t id = 0;                  // stable for the project's life
  std::optional<std::int64_t> scan_id;  // the scan it was taken with; none: no scan
  acquisition::ScanImage image;         // data empty unless asked for
};

struct StoredScanSummary {
  std::int64_t id = 0;  // the project's id of the scan, stable for the project's life
  acquisition::ScanSummary summary;
};

// kPending: a long command still being written by a running process;
// kInterrupted: one whose process (on this machine) is gone, so nothing of
// it was stored and the next writer removes it.
enum class CommandState { kPending, kDone, kUndone, kInterrupted };

// One journal entry.
struct CommandRecord {
  std::int64_t id = 0;   // increasing in the order the commands were begun; never reused
  std::string name;      // "import", "geometry", "register", "merge", "migrate", …
  std::string settings;  // JSON: the command's whole settings, enough to replay it
  std::string result;    // JSON: what it did (counts, report)
  CommandState state = CommandState::kDone;
  bool undoable = true;    // false for the migration of a project older than the journal
  std::string created_at;  // UTC, ISO 8601
};

// A scan ready to be stored: its metadata and summary, and every channel
// encoded as a layer (range_m, valid, intensity, rgb, directions). Encoding
// (compression) is the expensive part, so it happens before the write.
struct EncodedScan {
  acquisition::Scan metadata;  // channels left empty; pose, angles, names as the scan's
  acquisition::ScanSummary summary;
  std::vector<EncodedLayer> layers;
  // Identifies the scan's data (its range and validity), whatever its name
  // or pose: the same scan imported twice has the same digest.
  std::int64_t content_digest = 0;
};

// Encodes every channel of `scan`. Asserts the scan is consistent
// (acquisition::check_consistency).
EncodedScan encode_scan(const acquisition::Scan& scan);

// EncodedScan::content_digest of `scan`, without encoding it.
std::int64_t scan_content_digest(const acquisition::Scan& scan);

// Deletes a project file with its SQLite side files (-journal, -wal, -shm).
// For a project the caller itself created and must not leave behind; errors
// are ignored (the files may not exist).
void remove_project_files(const std::filesystem::path& file);

class Project {
 public:
  class Edit;
  class LongCommand;
  class ReadSnapshot;
  class Batch;
  class Draft;

  // Opens an existing project for reading and writing. Never creates or
  // recreates the file. Throws core::InputError, leaving the file untouched,
  // when it is missing, a directory, empty, not an SQLite database, another
  // application's database, a project of a newer schema version, or damaged;
  // core::RuntimeFailure when it cannot be opened for writing or another
  // writer keeps it locked for longer than kBusyTimeoutMs. Older schema
  // versions are migrated in one transaction.
  static Project open(const std::filesystem::path& file);

  // Opens a project for reading only (info, export, history): as open()
  // where the file and its folder are writable (an older schema is
  // migrated), otherwise as open_read_only().
  static Project open_for_reading(const std::filesystem::path& file);

  // Opens a project without ever changing its file (check): read-only, which
  // also works on write-protected media (as SQLite's "immutable" file when
  // not even its shared-memory file can be made and the write-ahead log is
  // empty). A project of an older schema version is not migrated:
  // core::RuntimeFailure saying how to upgrade it. Writing through it throws
  // core::RuntimeFailure.
  static Project open_read_only(const std::filesystem::path& file);

  // Creates a new, empty project. The file appears complete or not at all
  // (built under a temporary name, then moved into place without replacing
  // anything), so another process never sees it half made. Throws
  // core::InputError when the file already exists (it is never overwritten)
  // or its folder does not exist, core::RuntimeFailure when it cannot be
  // written; nothing is left behind.
  static Project create(const std::filesystem::path& file);

  // A new project that nobody sees until it is published: built and filled
  // under a temporary name beside `file` (an import into a new project
  // writes its scans into the draft), then moved into place whole. Throws as
  // create(); the draft's temporary file is removed unless published.
  static Draft create_draft(const std::filesystem::path& file);

  // open() when `file` exists, else create(); when another process creates
  // it first, opens that one. `created` (when given) tells which happened.
  static Project open_or_create(const std::filesystem::path& file, bool* created = nullptr);

  Project(Project&&) noexcept;
  Project& operator=(Project&&) noexcept;
  ~Project();  // closes the connection; an open Edit must be gone by then

  // The file as passed to open/create.
  const std::filesystem::path& path() const { return file_; }

  // PRAGMA user_version of the open file; kProjectSchemaVersion after open().
  int schema_version() const;

  // A number that changes with every committed edit, undo and redo, from
  // any process. A stage reads it before computing and passes it to
  // begin_command, which refuses to write when a command since changed data
  // the stage read (command_footprint.hpp).
  std::int64_t revision() const;
  // The revision at which `data` last changed (by a command, an undo or a
  // redo); 0 when none has since scanbench began keeping it.
  std::int64_t changed_at(ProjectData data) const;

  // ---- Scans -------------------------------------------------------------

  // Every scan's summary (sizes, channel presence, current pose and world
  // bounds, scanner metadata) ordered by id, without reading channel data.
  std::vector<StoredScanSummary> scans() const;

  // Which of a scan's optional channels load_scan reads (range and validity
  // it always reads): a stage that reads neither intensity nor colour
  // saves their decoding and memory.
  struct ScanChannels {
    bool intensity = true;
    bool color = true;
  };

  // The scan stored under `id` at its current pose, its channels
  // bit-identical to what insert_scan stored; those `channels` leaves out
  // are empty. Throws core::InputError "no scan with id N" when there is
  // none (or its import was undone), and names the scan and layer when its
  // data is damaged.
  acquisition::Scan load_scan(std::int64_t id, ScanChannels channels) const;
  acquisition::Scan load_scan(std::int64_t id) const { return load_scan(id, ScanChannels{}); }
  // The same without its per-pixel arrays (acquisition::without_arrays):
  // its name, grid size, angle model, pose and scanner, for a stage that
  // reads its layers by rows (layer_rows.hpp).
  acquisition::Scan load_scan_description(std::int64_t id) const;

  // Stores a new scan (metadata, pose, summary, channel layers) as part of
  // `edit` and returns its id, which no other scan of the project ever gets.
  std::int64_t insert_scan(Edit& edit, const EncodedScan& scan);

  // The live scan whose data (range and validity) has `digest`
  // (EncodedScan::content_digest), or none.
  std::optional<std::int64_t> scan_with_content(std::int64_t digest) const;

  // Moves scan `id` to scan.T_world_scan as part of `edit`: a new pose
  // version with the world bounds of `scan`, which must be the stored scan
  // with only its pose changed (asserted on size, and a finite pose), and
  // the scanner position carried along rigidly (T_new · T_old⁻¹ applied to
  // the old one). Throws core::InputError when there is no such scan.
  void set_pose(Edit& edit, std::int64_t id, const acquisition::Scan& scan);
  // The same with the pose and its world bounds given (acquisition::
  // world_bounds of the stored scan at that pose), for a stage that no
  // longer holds the scan.
  void set_pose(Edit& edit, std::int64_t id, const Eigen::Isometry3d& T_world_scan,
                const std::optional<Eigen::AlignedBox3d>& bbox_world);

  // ---- Layers (modeling/store/layer_store.hpp) -----------------------------------------

  // Writes a new version of layer `layer.name` of scan `id` as part of
  // `edit`. Asserts the layer has one element per pixel of the scan and,
  // for the names layer_store.hpp lists, their type; throws core::InputError when
  // there is no such scan.
  void put_layer(Edit& edit, std::int64_t id, const EncodedLayer& layer);

  // The same, from a layer written by rows (layer_rows.hpp), copied into
  // the project in pieces; asserts every row was written.
  void put_layer(Edit& edit, std::int64_t id, const LayerRowWriter& layer);

  // Removes layer `name` of scan `id` as part of `edit` (a version saying
  // "none": undo brings the earlier version back). No effect on a layer the
  // scan does not have; throws core::InputError when there is no such scan.
  void remove_layer(Edit& edit, std::int64_t id, std::string_view name);

  // The current version of layer `name` of scan `id`, decoded into values
  // of T as encode_layer took them, and checked against `type` and the
  // scan's pixel count; none when the scan has no such layer. Throws
  // core::InputError naming scan and layer when the stored layer has another
  // type or size, or is damaged.
  template <typename T>
  std::optional<std::vector<T>> load_layer(std::int64_t id, std::string_view name,
                                           ElementType type) const {
    std::optional<std::vector<T>> values;
    const bool found = read_layer(id, name, type, [&values](std::size_t bytes) {
      assert(bytes % sizeof(T) == 0 && "layer elements are not whole values of T");
      values.emplace();
      core::reserve_mapped(*values, bytes / sizeof(T));  // in bulk: a layer may be a gigabyte
      values->resize(bytes / sizeof(T));
      return std::as_writable_bytes(std::span<T>(*values));
    });
    if (!found) return std::nullopt;
    return values;
  }

  // The current version of layer `name` of scan `id`, to be read a band
  // of rows at a time (layer_rows.hpp), checked as load_layer checks it
  // (its type against `type` when given); none when the scan has no such
  // layer.
  std::optional<LayerRowReader> open_layer_rows(std::int64_t id, std::string_view name,
                                                std::optional<ElementType> type) const;

  // Names of the current layers of scan `id`, sorted.
  std::vector<std::string> layer_names(std::int64_t id) const;

  // ---- The object tree --------------------------------------------------

  // The live nodes, as the newest done command that wrote each left it,
  // ordered by id. Throws core::InputError naming the node when its row is
  // damaged.
  std::vector<ObjectNode> object_nodes() const;

  // The same nodes by id. Both come from a copy of the tree the project
  // keeps between commands of this connection, so a script of many tree
  // commands reads and verifies the nodes' rows only once.
  std::map<std::int64_t, ObjectNode> object_tree() const;

  // The ids of the live nodes called `name`, in id order.
  std::vector<std::int64_t> nodes_named(std::string_view name) const;

  // An id no node of the file has (one above the largest ever stored that
  // is still in the journal: the ids of discarded commands' nodes may come
  // back).
  std::int64_t new_node_id() const;

  // Writes a new version of node `node.id` as part of `edit`. Asserts a
  // positive id, a parent other than itself, a non-negative point count and
  // finite figures; the tree's consistency (parents exist, no cycles) is the
  // caller's.
  void put_node(Edit& edit, const ObjectNode& node);

  // Deletes node `id` as part of `edit` (a version saying "deleted": undo
  // brings it back). No effect on a node that is not live.
  void remove_node(Edit& edit, std::int64_t id);

  // ---- Colour corrections of scans (color_edit.hpp) --------------------------

  // The current correction of every live scan that has one, by scan id.
  // Throws core::InputError naming the scan when its row is damaged.
  std::map<std::int64_t, ScanColorCorrection> scan_color_corrections() const;

  // Writes a new version of scan `id`'s correction as part of `edit` (the
  // identity removes it in effect). Throws core::InputError when there is
  // no such scan.
  void put_scan_color_correction(Edit& edit, std::int64_t id,
                                 const ScanColorCorrection& correction);

  // ---- Sources and images of scans (acquisition/scan_source.hpp) ----------

  // Stores what the source file says of new scan `id` as part of the
  // `edit` that inserted it.
  void put_scan_source(Edit& edit, std::int64_t id, const acquisition::ScanSource& source);

  // The source of every live scan that has one (scans imported before
  // schema 7 have none), by scan id. Throws core::InputError naming the
  // scan when its row is damaged.
  std::map<std::int64_t, acquisition::ScanSource> scan_sources() const;

  // Stores an image as part of `edit`, tied to scan `scan_id` (asserted to
  // be a scan of the project or of this edit) whose pose is `T_world_scan`,
  // or to no scan (`scan_id` empty), and returns its id. A tied image keeps
  // its pose relative to its scan, so it follows the scan when
  // registration moves it. Throws core::InputError for an image that is
  // neither JPEG nor PNG.
  std::int64_t insert_image(Edit& edit, std::optional<std::int64_t> scan_id,
                            const Eigen::Isometry3d& T_world_scan,
                            const acquisition::ScanImage& image);

  // The images of the live import commands, by id, tied ones at their
  // scan's current pose; with `with_data` their encoded bytes too, checked
  // against their CRC. Throws core::InputError
  // naming the image when its row or data is damaged.
  std::vector<StoredImage> images(bool with_data) const;

  // ---- Commands and the journal ------------------------------------------

  // Starts command `name` (with its whole settings as JSON): takes the write
  // lock, discards undone commands (they can no longer be redone), and opens
  // the journal entry. When `based_on_revision` is given and a command since
  // (of another process, while the caller computed) changed data command
  // `name` reads (command_footprint.hpp), throws core::RuntimeFailure and
  // changes nothing. Throws
  // core::RuntimeFailure when another writer keeps the lock for longer than
  // kBusyTimeoutMs. Asserts no Edit is open on this project.
  Edit begin_command(std::string_view name, const std::string& settings_json,
                     std::optional<std::int64_t> based_on_revision = std::nullopt);

  // Starts a command written in parts (see above): records it as pending,
  // in a transaction of its own. `based_on_revision` is checked now and
  // again when it finishes. Throws as begin_command.
  LongCommand begin_long_command(std::string_view name, const std::string& settings_json,
                                 std::optional<std::int64_t> based_on_revision = std::nullopt);

  // Reads that must agree with each other (an export of masks, poses and
  // channels) see one state of the project while the returned snapshot
  // lives, whatever other processes commit meanwhile. Asserts no Edit is
  // open. Inside a Batch, which already sees one state, it does nothing.
  ReadSnapshot read_snapshot() const;

  // Makes the commands, undos and redos that follow one unit (a segment
  // script): what they write lands in the file when the batch commits, or
  // not at all, the journal's redo chain included. Takes the write lock at
  // once and holds it until the batch ends, so no other process writes in
  // between. Each Edit inside is a savepoint: a refused command rolls back
  // only itself. Throws core::RuntimeFailure when another writer keeps the
  // lock for longer than kBusyTimeoutMs. Asserts no Edit or Batch is open;
  // long commands cannot run inside one.
  Batch begin_batch();

  // The journal in journal order (done, then undone; pending and
  // interrupted commands last).
  std::vector<CommandRecord> history() const;

  // Marks the newest done command undone, in one transaction, and returns
  // it; none when there is nothing to undo: no done command, or the newest
  // one is what an older project held before it had a journal, or it is not
  // command `only` (when given: a caller taking back exactly what it did).
  std::optional<CommandRecord> undo(std::optional<std::int64_t> only = std::nullopt);

  // Marks the oldest undone command done again and returns it; none when
  // nothing was undone, or (when `only` is given) it is not command `only`.
  std::optional<CommandRecord> redo(std::optional<std::int64_t> only = std::nullopt);

  // The result of the newest done command called `name`, or none.
  std::optional<std::string> latest_result(std::string_view name) const;

  // The journal entry of the command that wrote the current version of
  // layer `name` of scan `id` (verified), or none when no done command did.
  std::optional<CommandRecord> layer_writer(std::int64_t id, std::string_view name) const;

  // A fingerprint of the values of the current version of layer `name` of
  // scan `id`: its type, element count, frame size and the frame's content
  // checksum (zstd's XXH64 of the values, its low 32 bits). Equal values
  // written by another command, as a stage run again writes them, give the
  // same one; none when the scan has no such layer. Reads the frame's end,
  // not its values.
  std::optional<std::string> layer_fingerprint(std::int64_t id, std::string_view name) const;

  // ---- Integrity ---------------------------------------------------------

  // Checks the whole file (`scanbench check`): SQLite's integrity and
  // foreign-key checks, the checksum of every record (scans, poses, journal
  // entries, undone ones included), and every layer decoded in full against
  // its zstd checksum and its element count. Reading verifies the records
  // it touches anyway; this reads everything. Damage is listed in the
  // report; only a file too damaged for SQLite to read its tables at all
  // throws core::InputError.
  struct CheckReport {
    std::vector<std::string> damage;  // one line each: what is damaged and how
    std::size_t records = 0;          // scans, poses, journal entries and node versions checked
    std::size_t layers = 0;           // layer versions decoded
  };
  CheckReport check() const;

 private:
  struct CloseConnection {
    void operator()(sqlite3* db) const noexcept;
  };
  using Connection = std::unique_ptr<sqlite3, CloseConnection>;

  // What is open on the connection, and its object tree
  // (modeling/store/object_tree_cache.hpp).
  struct ConnectionState;

  Project(std::filesystem::path file, Connection db);
  sqlite3* db() const;
  // Throws core::RuntimeFailure when the batch open on `db` is gone (SQLite
  // rolled it back after a write error) or a refused Edit in it could not
  // be rolled back: nothing more may be written, nor the batch committed.
  static void require_open_batch(sqlite3* db, ConnectionState& connection, const std::string& file);
  // The tree the connection keeps, brought up to the current revision;
  // none inside an Edit, whose writes it does not hold yet. Valid until the
  // next write.
  const std::map<std::int64_t, ObjectNode>* current_tree() const;
  // The live nodes as their rows say, each verified.
  std::map<std::int64_t, ObjectNode> read_tree() const;
  std::string file_name() const { return file_.string(); }
  // rows × columns of live scan `id` (or one `edit` is creating); throws
  // core::InputError when there is none.
  std::size_t stored_pixel_count(std::int64_t id, const Edit* edit = nullptr) const;
  // Asserts that `edit` is open on this project.
  void check_edit(const Edit& edit) const;
  // The summary of live scan `id` at its current pose; throws
  // core::InputError when there is none.
  StoredScanSummary current_summary(std::int64_t id) const;
  // Reads, checksums verified, what the project now holds of everything
  // command `command_id` wrote a version of (after an undo the versions
  // before it, after a redo its own): every live scan and pose, node,
  // colour correction, source and image (its data checked against its
  // CRC), and each layer the command wrote, its current version decoded in
  // full. Throws core::InputError naming the damage.
  void verify_current_rows(std::int64_t command_id) const;
  // Reads the current version of layer `name` of live scan `id`, its row
  // verified and its data decoded a band of rows at a time (a layer may be
  // larger than memory); nothing when there is none.
  void verify_current_layer(std::int64_t id, std::string_view name) const;
  // Decodes the current version of a layer into the buffer `allocate`
  // returns for its size in bytes; false when there is none. Refused as
  // damaged when its type is not `expected` (any type it may hold when
  // none).
  bool read_layer(std::int64_t id, std::string_view name, std::optional<ElementType> expected,
                  const std::function<std::span<std::byte>(std::size_t bytes)>& allocate) const;

  std::filesystem::path file_;
  Connection db_;
  std::unique_ptr<ConnectionState> connection_;
};

}  // namespace scanbench::store

// The nested classes: Project::Edit, LongCommand, ReadSnapshot, Batch, Draft.
#include "modeling/store/project_transactions.hpp"  // IWYU pragma: export
