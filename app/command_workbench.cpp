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
  command->add_option("--size", options->width, "Window width [pixels]")
      ->check(CLI::Range(960, 4096))
      ->capture_default_str();
  command->callback([options] {
    if (!options->screenshot.empty() && options->screenshot.extension() != ".png")
      throw CLI::ValidationError("--screenshot", "must name a .png file");
    for (const auto& [option, file] :
         {std::pair{"--screenshot", options->screenshot}, std::pair{"--layout", options->layout}}) {
      const std::filesystem::path folder = file.parent_path().empty() ? "." : file.parent_path();
      if (!file.empty() && !std::filesystem::is_directory(folder))
        throw CLI::ValidationError(option, "the folder " + folder.string() + " does not exist");
    }
    options->height = options->width * 5 / 8;
    workbench::run_workbench(*options);
  });
}

}  // namespace scanbench::app
