#pragma once
/// \file scene_runner.hpp
/// Runs a scene: builds the mesh (read or box → validate_tet_mesh → drop unreferenced vertices →
/// orient_tets), the Simulation, locates the probes, then steps to the end writing probes.csv,
/// reactions.csv, the VTK series and stats.json into the output folder.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>

#include "strata/app/scene.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/meshing_report.hpp"

namespace strata::app {

/// The scene's mesh, ready for simulation.
struct PreparedMesh {
  TetMesh mesh;
  std::string source;          ///< the mesh file or "box"
  Index removed_vertices = 0;  ///< vertices no tet referenced
  Index reoriented_tets = 0;   ///< tets flipped to positive orientation
  /// Set when the mesh was generated from "mesh": {"surface": ...} (or taken from the cache).
  std::optional<MeshingReport> meshing;
};

/// Reads (or builds, or generates from a surface) and prepares the scene's mesh. InputErrors name
/// the scene file and key ("scene.json: mesh.file: <reader message naming the mesh file>").
/// Generated meshes are cached in mesh_cache_dir(scene); a non-watertight surface prints a
/// warning to std::cerr.
PreparedMesh prepare_scene_mesh(const Scene& scene);

struct RunOptions {
  std::filesystem::path output_dir;  ///< empty: default_output_dir(scene)
  bool quiet = false;                ///< no info lines and no summary (warnings still print)
  bool progress = false;             ///< draw a progress bar on stderr
  /// Non-empty: rewrite this file with "<fraction done> <seconds elapsed>" as the run goes
  /// (at most twice a second), for a program that watches the run (experiment.py's ETA).
  std::filesystem::path progress_file;
  std::ostream* log = nullptr;  ///< info and summary lines (nullptr: std::cout)
  /// Scenes with a hierarchy: called with the run before the first step and after every step
  /// (e.g. to record the active cut, precompute_command.hpp).
  std::function<void(const AdaptiveSimulation&)> on_step;
};

struct RunSummary {
  std::string status = "ok";  ///< "ok" | "diverged"
  std::string message;        ///< the divergence message
  long steps = 0;
  int frames = 0;
  double wall_seconds = 0.0;
  double stable_dt_estimate = 0.0;
  std::filesystem::path output_dir;
};

/// `<scene folder>/out/mesh_cache`: generated meshes, keyed by surface content and parameters.
std::filesystem::path mesh_cache_dir(const Scene& scene);

/// `<scene folder>/out/<scene stem>`.
std::filesystem::path default_output_dir(const Scene& scene);

/// Tolerance for locating probes: 1e-3 × the rest mesh's bounding-box diagonal.
inline constexpr double kProbeToleranceFactor = 1e-3;

/// Runs the scene and writes its outputs. Throws InputError for bad input (before any step) and
/// DivergenceError if the run diverges — after writing everything up to the last good frame and
/// stats.json with status "diverged".
RunSummary run_scene(const Scene& scene, const RunOptions& options);

}  // namespace strata::app
