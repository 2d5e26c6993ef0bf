// scanbench workbench PROJECT [--replay EVENTS.json] [--screenshot OUT.png] [--layout OUT.json]
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include "app/commands.hpp"
#include "app/workbench/workbench.hpp"

namespace scanbench::app {

void add_workbench_command(CLI::App& app) {
  auto options = std::make_shared<workbench::WorkbenchOptions>();
  CLI::App* command = app.add_subcommand(
      "workbench",
      "Open the interactive workbench: the scans, the panoramic image view with the "
      "segmentation tools (seed, lasso, barrier), the object manager, the colour editor and the "
      "3D view, in one window (needs a display; run under xvfb-run -a without one). Ctrl+Z and "
      "Ctrl+Y undo and redo through the project's journal. docs/workbench.md is the user guide.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option("--replay", options->replay,
                   "Feed the recorded mouse and key events of this file (JSON), then exit")
      ->check(CLI::ExistingFile);
  command->add_option("--screenshot", options->screenshot,
                      "Save the window as PNG: after the replay, or after the first frame");
  command->add_option("--layout", options->layout,
                      "Write where the widgets and views are (JSON), for writing replays");
  command->add_option("--record", options->record,
                      "Record the session's mouse and key input as a replay file (JSON), "
                      "written when the window closes");
  command->add_flag("--read-only", options->read_only,
                    "Look without changing the project: every edit is refused, nothing is "
                    "journaled (automatic when the file cannot be written)");
  command
      ->add_option("--size", options->width,
                   "Window width [pixels], the height 5/8 of it (default: fill the screen; "
                   "1280 with --replay or --record)")
      ->check(CLI::Range(960, 4096));
  command->callback([options] {
    if (!options->screenshot.empty() && options->screenshot.extension() != ".png")
      throw CLI::ValidationError("--screenshot", "must name a .png file");
    if (!options->record.empty() && options->record.extension() != ".json")
      throw CLI::ValidationError("--record", "must name a .json file");
    if (!options->record.empty() && std::filesystem::exists(options->record))
      throw CLI::ValidationError(
          "--record", options->record.string() + " exists: name a new file, or remove it first");
    for (const auto& [option, file] :
         {std::pair{"--screenshot", options->screenshot}, std::pair{"--layout", options->layout},
          std::pair{"--record", options->record}}) {
      const std::filesystem::path folder = file.parent_path().empty() ? "." : file.parent_path();
      if (!file.empty() && !std::filesystem::is_directory(folder))
        throw CLI::ValidationError(option, "the folder " + folder.string() + " does not exist");
    }
    // A replay's positions hold for the window size it was recorded at:
    // replays and recordings open at 1280 × 800 unless --size says otherwise.
    if (options->width == 0 && (!options->replay.empty() || !options->record.empty()))
      options->width = 1280;
    options->height = options->width * 5 / 8;
    workbench::run_workbench(*options);
  });
}

}  // namespace scanbench::app
