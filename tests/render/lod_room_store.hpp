// The room of tests/segmentation/room_scene.hpp in a project and its
// level-of-detail store, built once per test executable: a deep tree of a
// small model (leaves of at most 2000 points).
#pragma once

#include <filesystem>

#include "modeling/lod/build_lod.hpp"
#include "modeling/room_project.hpp"
#include "render/lod_frame_plan.hpp"
#include "support/test_support.hpp"

namespace scanbench::render {

struct LodRoomStore {
  scanbench::test::ScratchDir dir;
  std::filesystem::path store;
  LodHierarchy hierarchy;
};

inline const LodRoomStore& lod_room_store() {
  static LodRoomStore room;  // its folder goes when the executable exits
  static const bool built = [] {
    store::Project project = store::Project::create(room.dir / "room.sbproj");
    modeling::store_room(project);
    core::Progress quiet;
    lod::LodBuildSettings settings;
    settings.threads = 1;
    settings.octree.max_leaf_points = 2000;
    room.store = lod::build_lod(project, settings, quiet).store;
    room.hierarchy = LodHierarchy::of(lod::LodStore::open(room.store));
    return true;
  }();
  static_cast<void>(built);
  return room;
}

}  // namespace scanbench::render
