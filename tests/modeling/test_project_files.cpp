// Project: files that must be refused untouched, and crash safety.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "core/errors.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using core::InputError;
using test::RawDatabase;
using test::ScratchDir;
using test::tiny_scan;
using ::testing::HasSubstr;

void write_file(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

// Opens `file` expecting a refusal whose message contains `problem`; the file
// must keep every byte and gain no SQLite side files. open_or_create must
// refuse it the same way rather than overwrite it.
void expect_refused(const std::filesystem::path& file, const std::string& problem) {
  const std::string before = test::read_file_bytes(file);
  const std::function<store::Project(const std::filesystem::path&)> openers[] = {
      [](const std::filesystem::path& f) { return store::Project::open(f); },
      [](const std::filesystem::path& f) { return store::Project::open_or_create(f); },
      [](const std::filesystem::path& f) { return store::Project::open_for_reading(f); }};
  for (const auto& opener : openers) {
    try {
      opener(file);
      ADD_FAILURE() << "expected core::InputError for " << file;
    } catch (const core::InputError& error) {
      EXPECT_EQ(error.file(), file.string());
      EXPECT_THAT(error.what(), HasSubstr(problem));
    }
    EXPECT_EQ(test::read_file_bytes(file), before);
    EXPECT_TRUE(test::no_side_files(file));
  }
}

void make_foreign_database(const std::filesystem::path& file, const char* journal_mode) {
  RawDatabase raw(file);
  raw.execute(std::string("PRAGMA journal_mode = ") + journal_mode);
  raw.execute("PRAGMA application_id = 1179537988; PRAGMA user_version = 1");
  raw.execute("CREATE TABLE scans (id INTEGER PRIMARY KEY, payload TEXT)");
  raw.execute("INSERT INTO scans (payload) VALUES ('not ours')");
}

// The POSIX locks this process holds on `file`, from /proc/locks: the
// locks SQLite takes, which other processes' connections respect.
std::size_t locks_held_on(const std::filesystem::path& file) {
  struct stat status {};
  if (::stat(file.c_str(), &status) != 0) return 0;
  std::ifstream locks("/proc/locks");
  std::size_t held = 0;
  std::string line;
  while (std::getline(locks, line)) {
    // "1: POSIX  ADVISORY  READ 1234 08:01:5678 128 128"; waiters carry "->".
    if (line.find("->") != std::string::npos) continue;
    std::istringstream fields(line);
    std::string index, kind, mode, access, pid, device;
    fields >> index >> kind >> mode >> access >> pid >> device;
    if (kind != "POSIX" || pid != std::to_string(::getpid())) continue;
    const std::string inode = device.substr(device.rfind(':') + 1);
    if (std::stoull(inode) == static_cast<unsigned long long>(status.st_ino)) ++held;
  }
  return held;
}

// SQLite's locks belong to the process, not to a descriptor: had opening a
// project read its header through a descriptor of its own, closing that
// would drop the locks of the connections already open, and another
// process could then checkpoint and delete the write-ahead log they still
// write to (their next commands lost). A bench run lost them so.
TEST(ProjectFiles, OpeningAProjectAgainKeepsTheLocksOfItsOpenConnections) {
  const ScratchDir dir;
  const auto file = dir / "shared.sbproj";
  store::Project project = store::Project::create(file);
  project.revision();  // reading the log: a lock held while the connection lives
  const std::size_t held = locks_held_on(file);
  ASSERT_GT(held, 0u) << "no lock to keep: /proc/locks lists none for the project";
  { store::Project::open_read_only(file).revision(); }
  EXPECT_EQ(locks_held_on(file), held);
  { store::Project::open(file).revision(); }
  EXPECT_EQ(locks_held_on(file), held);
  // Outputs are checked not to be projects (never overwritten) the same way.
  EXPECT_TRUE(core::is_project_file(file));
  EXPECT_EQ(locks_held_on(file), held);
}

TEST(ProjectFiles, RefusesATextFile) {
  const ScratchDir dir;
  const auto file = dir / "x.sbproj";
  write_file(file, "this is a shopping list, not a project\n");
  expect_refused(file, "not an SQLite database");
}

TEST(ProjectFiles, RefusesAnEmptyFile) {
  const ScratchDir dir;
  const auto file = dir / "empty.sbproj";
  write_file(file, "");
  expect_refused(file, "file is empty");
}

TEST(ProjectFiles, RefusesADirectory) {
  const ScratchDir dir;
  const auto folder = dir / "folder.sbproj";
  std::filesystem::create_directory(folder);
  EXPECT_THROW(store::Project::open(folder), core::InputError);
  EXPECT_THROW(store::Project::open_or_create(folder), core::InputError);
  EXPECT_TRUE(std::filesystem::is_empty(folder));
}

TEST(ProjectFiles, RefusesAMissingFileWithoutCreatingIt) {
  const ScratchDir dir;
  const auto file = dir / "gone.sbproj";
  EXPECT_THROW(store::Project::open(file), core::InputError);
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(ProjectFiles, RefusesAnotherApplicationsDatabase) {
  for (const char* journal_mode : {"DELETE", "WAL"}) {
    const ScratchDir dir;
    const auto file = dir / "other.sbproj";
    make_foreign_database(file, journal_mode);
    expect_refused(file, "another application, application_id 0x464e5244");
  }
}

TEST(ProjectFiles, RefusesAPlainSqliteDatabase) {
  const ScratchDir dir;
  const auto file = dir / "plain.sbproj";
  { RawDatabase(file).execute("CREATE TABLE t (x)"); }
  expect_refused(file, "application_id 0x0");
}

TEST(ProjectFiles, RefusesANewerSchema) {
  const ScratchDir dir;
  const auto file = dir / "future.sbproj";
  { store::Project project = store::Project::create(file); }
  { RawDatabase(file).execute("PRAGMA user_version = 99"); }
  expect_refused(file, "project schema version 99 is newer than this scanbench (" +
                           std::to_string(store::kProjectSchemaVersion) + "); upgrade scanbench");
}

// The version bump sits only in the -wal file while another connection keeps
// it from being checkpointed: the header check passes, SQLite's must refuse.
TEST(ProjectFiles, RefusesANewerSchemaThatIsOnlyInTheLog) {
  const ScratchDir dir;
  const auto file = dir / "future.sbproj";
  { store::Project project = store::Project::create(file); }
  RawDatabase newer(file);
  newer.execute("PRAGMA wal_autocheckpoint = 0; PRAGMA user_version = 99");
  const std::string before = test::read_file_bytes(file);
  try {
    store::Project::open(file);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("project schema version 99 is newer"));
  }
  EXPECT_EQ(test::read_file_bytes(file), before);
}

TEST(ProjectFiles, RefusesADamagedProjectUntouched) {
  const ScratchDir dir;
  const auto file = dir / "damaged.sbproj";
  {
    store::Project project = store::Project::create(file);
    test::insert_committed(project, tiny_scan(true, true, true));
  }
  std::string bytes = test::read_file_bytes(file);
  ASSERT_GT(bytes.size(), 400u);
  // Page 1 past the 100-byte file header: the root of the schema table.
  std::fill(bytes.begin() + 100, bytes.begin() + 400, '\xab');
  write_file(file, bytes);
  expect_refused(file, "project file is damaged");
}

// Found by fuzz_project: SQLite opens a file whose header gives a write
// version above 2 read-only, so its migration failed as if the disk were
// read-only (a runtime failure) instead of as the damaged file it is.
TEST(ProjectFiles, RefusesAHeaderOfAnUnknownSqliteFileFormatUntouched) {
  const ScratchDir dir;
  for (const int byte : {18, 19}) {
    const auto file = dir / ("format " + std::to_string(byte) + ".sbproj");
    std::filesystem::copy_file(test::fixture("projects/version1.sbproj"), file);
    std::string bytes = test::read_file_bytes(file);
    bytes[static_cast<std::size_t>(byte)] = '\x04';
    write_file(file, bytes);
    expect_refused(file, "SQLite file format versions");
    EXPECT_EQ(test::read_file_bytes(file), bytes);
  }
}

TEST(ProjectFiles, RefusesTheCommittedBadFixtures) {
  const ScratchDir dir;
  for (const std::string name : {"project_not_sqlite.sbproj", "project_foreign_sqlite.sbproj"}) {
    const auto fixture = test::fixture("bad/" + name);
    ASSERT_TRUE(std::filesystem::exists(fixture));
    // Refused from a copy, so that a regression cannot damage the fixture.
    const auto copy = dir / name;
    std::filesystem::copy_file(fixture, copy);
    expect_refused(copy, "not a scanbench project");
    EXPECT_EQ(test::read_file_bytes(copy), test::read_file_bytes(fixture));
  }
}

// Large and incompressible enough (about 5 MB) to overflow SQLite's page
// cache, so uncommitted pages reach the -wal file before the kill.
acquisition::Scan large_scan() {
  acquisition::Scan scan = tiny_scan(true, true, false, 1024, 1024);
  std::mt19937 bits(7);
  for (float& range : scan.range_m) range = static_cast<float>(bits() % 100000) * 1.0e-3f;
  scan.name = "killed mid-import";
  return scan;
}

// Child: open, begin, insert, report 'K' through the pipe, then wait to be
// killed with the transaction open. Never returns.
[[noreturn]] void child_insert_and_wait(const std::filesystem::path& file, int report_fd) {
  char status = 'E';
  try {
    store::Project project = store::Project::open(file);
    store::Project::Edit edit = project.begin_command("import", "{}");
    project.insert_scan(edit, store::encode_scan(large_scan()));
    status = 'K';
    [[maybe_unused]] const auto ignored = ::write(report_fd, &status, 1);
    for (;;) ::pause();
  } catch (...) {
    [[maybe_unused]] const auto ignored = ::write(report_fd, &status, 1);
  }
  ::_exit(1);
}

void kill_during_insert(const std::filesystem::path& file) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    child_insert_and_wait(file, fds[1]);
  }
  ::close(fds[1]);
  char status = 0;
  EXPECT_EQ(::read(fds[0], &status, 1), 1);
  ::close(fds[0]);
  ::kill(child, SIGKILL);
  int wait_status = 0;
  ASSERT_EQ(::waitpid(child, &wait_status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == SIGKILL);
  ASSERT_EQ(status, 'K') << "the child failed before the kill";
}

class ProjectKill : public ::testing::TestWithParam<int> {};

TEST_P(ProjectKill, SigkillMidTransactionLeavesTheCommittedStateOnly) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  std::vector<std::int64_t> ids_before;
  {
    store::Project project = store::Project::create(file);
    for (int i = 0; i < GetParam(); ++i) {
      ids_before.push_back(test::insert_committed(project, tiny_scan(i % 2 == 0, true, true)));
    }
  }
  kill_during_insert(file);
  EXPECT_GT(std::filesystem::file_size(file.string() + "-wal"), 0u)
      << "the kill should leave uncommitted pages in the log";

  store::Project project = store::Project::open(file);
  std::vector<std::int64_t> ids_after;
  for (const auto& stored : project.scans()) ids_after.push_back(stored.id);
  EXPECT_EQ(ids_after, ids_before);
  EXPECT_EQ(RawDatabase(file).text("PRAGMA integrity_check"), "ok");
  for (const std::int64_t id : ids_before) {
    test::expect_identical(project.load_scan(id), tiny_scan(id % 2 == 1, true, true));
  }
  // The dead writer's lock is gone: a new edit commits.
  test::insert_committed(project, tiny_scan(true, false, false));
  EXPECT_EQ(project.scans().size(), ids_before.size() + 1);
}

INSTANTIATE_TEST_SUITE_P(ScansBefore, ProjectKill, ::testing::Values(0, 1));

}  // namespace
}  // namespace scanbench::modeling
