#pragma once
/// \file precompute_command.hpp
/// `strata precompute SCENE.json [SCENE2.json …] --out cut.json`: runs the scenes adaptively,
/// records per tree node when it was refined (CutRecorder) and writes the cut that captures every
/// run — one static cut, or a schedule of `windows` cuts over time — for
/// "hierarchy": {"mode": "precomputed", "cut": "cut.json"}; optionally also as a conforming tet
/// mesh (conforming_mesh.hpp).
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace strata::app {

struct PrecomputeCommand {
  std::vector<std::filesystem::path> scenes;  ///< each with a "hierarchy" over the same mesh
  std::filesystem::path output;               ///< cut.json
  std::filesystem::path mesh;                 ///< optional conforming mesh (.vtu, .mesh, …)
  std::vector<std::string> overrides;         ///< --set, applied to every scene
  /// hierarchy.tolerance of the recorded runs; 0: half of each scene's own.
  double tolerance = 0.0;
  int windows = 1;     ///< cuts in the schedule (equal windows of the longest run)
  bool quiet = false;  ///< no info lines
  bool progress = false;
};

/// Runs the command. The recorded runs write their outputs (without VTK frames) to
/// `<output stem>_runs/<scene stem>/` beside the cut file. Throws InputError naming the scene or
/// file on bad input (no hierarchy, different meshes, windows < 1, an unwritable output).
void run_precompute_command(const PrecomputeCommand& command, std::ostream& log);

}  // namespace strata::app
