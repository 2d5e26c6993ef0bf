// The room of tests/segmentation/room_scene.hpp stored in a project with
// its geometry, and its pixels by viewing direction: the scene the
// segmentation's and the render model's project tests work on.
#pragma once

#include <cmath>
#include <cstdint>
#include <tuple>
#include <utility>

#include "modeling/selection_commands.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"
#include "project_test_support.hpp"
#include "segmentation/room_scene.hpp"

namespace scanbench::modeling {

// A project holding the room of tests/segmentation/room_scene.hpp with its
// geometry; returns the scan's id.
inline std::int64_t store_room(store::Project& project) {
  const test::RoomScan& room = test::shared_room();
  const std::int64_t id = test::insert_committed(project, room.scan);
  store::Project::Edit edit = project.begin_command("geometry", "{}");
  for (const store::EncodedLayer& layer : store::encode_geometry(room.geometry))
    project.put_layer(edit, id, layer);
  edit.commit("{}");
  return id;
}

// The pixel of the room looking at azimuth / elevation [deg] (0.5° grid).
inline std::pair<int, int> pixel_at(double azimuth_deg, double elevation_deg) {
  return {static_cast<int>(std::lround((30.0 - elevation_deg) / 0.5)),
          static_cast<int>(std::lround((azimuth_deg + 180.0) / 0.5 - 0.5)) % 720};
}

// A click of `channel` at azimuth / elevation [deg] of the room's scan.
inline SelectSettings select_at(std::int64_t scan, double azimuth_deg, double elevation_deg,
                                SelectMode mode = SelectMode::kReplace,
                                segmentation::Channel channel = segmentation::Channel::kNormal) {
  SelectSettings settings;
  settings.scan_id = scan;
  std::tie(settings.seed_row, settings.seed_col) = pixel_at(azimuth_deg, elevation_deg);
  settings.mode = mode;
  settings.grow = segmentation::default_grow_settings(channel);
  return settings;
}

}  // namespace scanbench::modeling
