// Identity checks, creation and migration of the project schema. Internal to
// modeling/ (used by project.cpp only).
//
// Schema history (PRAGMA user_version):
//   1  meta, scans, scan_channels.
//   2  scan_geometry (per-point footprint, normal, confidence, flags).
//   3  registration_runs, merge_masks.
//   4  commands (the journal), scan_poses, scan_layers; scan_channels,
//      scan_geometry, merge_masks and registration_runs move into them.
//   5  object_nodes (the object tree).
//   6  object_nodes.color_edit, scan_colors.
//   7  scan_sources, scan_images.
//   8  indexes of the commands that are undone or pending.
//   9  scans.layout: a grid, or a scattered scan (an unstructured cloud).
//  10  scan_layers.frame: the frame of a layer written by rows, last in its
//      row so that SQLite writes it in place.
// To change the schema: bump kProjectSchemaVersion and add a case to
// migrate_step() in schema.cpp that upgrades from the previous
// version. The version 1 script is never edited: new projects are created by
// it followed by every migration step.
#pragma once

#include <sqlite3.h>

#include <filesystem>
#include <string>

namespace scanbench::store::schema {

// Throws core::InputError when `file` is missing or not a regular file
// (without opening it).
void check_file_kind(const std::filesystem::path& file);

// Reads the 100-byte SQLite header of `file` through the descriptor of
// `db`, a connection to it that has read nothing yet: so nothing (not even
// a -wal or -shm file) is created beside files we refuse. Never through a
// descriptor of its own: closing that would drop the POSIX locks this
// process's connections hold on the file (they are the process's, not the
// descriptor's), and another process could then checkpoint and delete the
// write-ahead log under them, losing what they write next. Throws
// core::InputError when the file is empty, not an SQLite database, another
// application's database, or a project of a schema version newer than
// kProjectSchemaVersion or below 1.
void check_file_header(sqlite3* db, const std::filesystem::path& file);

// Sets the per-connection settings every project connection needs: foreign
// keys on, synchronous=FULL, busy timeout. Throws as sqlite::throw_error.
void configure_connection(sqlite3* db, const std::string& file);

// Creates the current schema in the empty database `db` in one transaction
// (version 1 script, then every migration step), then switches it to
// write-ahead logging. The application id and version are
// committed through the rollback journal, so they are in the main file even if
// a -wal file is lost later. Throws as sqlite::throw_error, and
// core::RuntimeFailure when the file system cannot do write-ahead logging.
void create_schema(sqlite3* db, const std::string& file);

// For a freshly opened existing project: repeats the identity checks on what
// SQLite reads (a -wal file can hold a newer version than the main file's
// header), checks the expected tables exist, and migrates an older schema to
// kProjectSchemaVersion in one transaction (then turns on write-ahead
// logging if it was off, so a refused
// migration leaves the file as it was). Throws core::InputError for a file
// that is not a project of a version this build reads or is damaged, and as
// sqlite::throw_error.
void check_and_migrate(sqlite3* db, const std::string& file);

// For a project opened read-only: the identity checks of check_and_migrate,
// with an older schema refused (core::RuntimeFailure: it cannot be migrated
// without writing) rather than migrated.
void check_readable(sqlite3* db, const std::string& file);

// PRAGMA user_version.
int read_schema_version(sqlite3* db, const std::string& file);

}  // namespace scanbench::store::schema
