// `scanbench workbench [PROJECT]`: the interactive workbench (seed 004
// Fig. 2(i)) in one window: scans, the panoramic image view with the
// segmentation tools, the object manager, the colour editor and the 3D
// view, drawn with Dear ImGui over GLFW (render/window). Every action goes
// through the project's commands; Ctrl+Z and Ctrl+Y undo and redo.
#pragma once

#include <filesystem>

namespace scanbench::app::workbench {

struct WorkbenchOptions {
  std::filesystem::path project;
  std::filesystem::path replay;      // events to feed, then exit (replay.hpp); empty: live
  std::filesystem::path screenshot;  // the window after the replay (.png); empty: none
  std::filesystem::path layout;      // where to write the widgets' centres (JSON); empty: none
  // Nothing is written (also when the file cannot be written: Session::cannot_write).
  bool read_only = false;
  // Where to record the session's input as a replay file; empty: nowhere.
  std::filesystem::path record;
  // The window's size [pixels]; 0: the screen's work area (a replay's
  // default is 1280 × 800, where its positions were recorded).
  int width = 0;
  int height = 0;
};

// Runs the workbench until its window closes or the replay ends. Throws
// core::InputError for a bad project or events file, core::RuntimeFailure
// without a display or an OpenGL 4.5 context.
void run_workbench(const WorkbenchOptions& options);

}  // namespace scanbench::app::workbench
