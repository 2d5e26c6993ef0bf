// The projects and readers the level-of-detail store's tests share
// (test_lod_store.cpp, test_lod_update.cpp).
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "core/progress.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/room_project.hpp"
#include "modeling/store/layer_store.hpp"
#include "support/test_support.hpp"

namespace scanbench::lod {

// The room twice: as scanned, and from a second station 0.4 m away whose
// merge kept two pixels in three; in the first, objects own some pixels and
// a band of them is deleted.
struct LodRoomProject {
  std::int64_t first = 0, second = 0;
  std::vector<std::uint32_t> membership;
  std::vector<std::uint8_t> keep;
};

inline LodRoomProject store_two_rooms(store::Project& project) {
  LodRoomProject room;
  room.first = modeling::store_room(project);
  acquisition::Scan moved = test::shared_room().scan;
  moved.T_world_scan.translation() += Eigen::Vector3d(0.4, -0.1, 0.0);
  moved.T_world_scan.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
  room.second = test::insert_committed(project, moved);
  const std::size_t n = moved.pixel_count();
  room.membership.assign(n, 0);
  room.keep.assign(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 7 == 0) room.membership[i] = 5;
    if (i / 720 == 100) room.membership[i] = store::kDeletedPoints;
    if (i % 3 == 0) room.keep[i] = 0;
  }
  store::Project::Edit edit = project.begin_command("geometry", "{}");
  for (const store::EncodedLayer& layer : store::encode_geometry(test::shared_room().geometry))
    project.put_layer(edit, room.second, layer);
  project.put_layer(edit, room.first,
                    store::encode_layer<std::uint32_t>(store::layer::kMembership,
                                                       store::ElementType::kU32, room.membership));
  project.put_layer(
      edit, room.second,
      store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8, room.keep));
  edit.commit("{}");
  return room;
}

inline LodBuildResult build_quietly(const store::Project& project, LodBuildSettings settings = {}) {
  core::Progress quiet;
  if (settings.threads == 0) settings.threads = 1;
  return build_lod(project, settings, quiet);
}

// Every node's description and points, by code.
inline std::map<std::uint64_t, std::pair<LodNodeInfo, std::vector<LodPoint>>> read_store(
    const LodStore& store) {
  std::map<std::uint64_t, std::pair<LodNodeInfo, std::vector<LodPoint>>> nodes;
  for (const LodNodeInfo& info : store.nodes())
    nodes[info.key.code()] = {info, store.read_points(info.key)};
  return nodes;
}

// Runs `work` in a child process (what it throws ends it with code 3)
// and, when `kill_after` is given, kills it with SIGKILL after that many
// seconds; returns once the child is gone.
inline void run_in_child(const std::function<void()>& work, std::optional<double> kill_after) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      work();
    } catch (...) {
      ::_exit(3);
    }
    ::_exit(0);
  }
  if (kill_after) {
    std::this_thread::sleep_for(std::chrono::duration<double>(*kill_after));
    ::kill(child, SIGKILL);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
}

}  // namespace scanbench::lod
