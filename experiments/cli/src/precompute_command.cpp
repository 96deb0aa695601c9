#include "strata/app/precompute_command.hpp"

#include <algorithm>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "strata/app/cut_file.hpp"
#include "strata/app/scene_parser.hpp"
#include "strata/app/scene_runner.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/hierarchy/conforming_mesh.hpp"

namespace strata::app {
namespace {

std::string json_number(double value) {
  std::ostringstream text;
  text << std::setprecision(17) << value;
  return text.str();
}

/// Every node refined in some window of `cut`.
std::vector<NodePath> union_of_windows(const PrecomputedCut& cut) {
  std::vector<NodePath> all;
  for (const CutWindow& window : cut.windows)
    for (const NodePath& path : window.refined)
      all.push_back(path);
  std::sort(all.begin(), all.end(),
            [](const NodePath& a, const NodePath& b) { return node_key(a) < node_key(b); });
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

}  // namespace

void run_precompute_command(const PrecomputeCommand& command, std::ostream& log) {
  if (command.scenes.empty()) throw InputError("precompute: no scene given");
  if (command.windows < 1) throw InputError("precompute: --windows must be >= 1");
  if (!(command.tolerance >= 0.0 && command.tolerance < 1.0))
    throw InputError("precompute: --tolerance must be in (0, 1)");
  if (command.output.extension() != ".json")
    throw InputError("precompute: --out " + command.output.string() + ": must be a .json file");
  if (!command.mesh.empty()) mesh_format_of(command.mesh);  // unknown extensions fail early
  // The scenes as written, to read their own tolerances; a window holds at least one step (or
  // load step) of the longest run.
  std::vector<Scene> originals;
  long longest = 0;
  for (const std::filesystem::path& file : command.scenes) {
    originals.push_back(load_scene(file, command.overrides));
    longest = std::max(longest, planned_steps(originals.back().solver));
  }
  if (command.windows > longest)
    throw InputError("precompute: --windows " + std::to_string(command.windows) + " exceeds the " +
                     std::to_string(longest) +
                     " steps of the longest run (a window holds at least one step)");

  CutRecorder recorder;
  TetMesh coarse;
  int levels = -1;
  double tolerance = 0.0;
  double end = 0.0;
  std::filesystem::path first;
  const std::filesystem::path runs_dir =
      command.output.parent_path() / (command.output.stem().string() + "_runs");
  for (std::size_t i = 0; i < command.scenes.size(); ++i) {
    const std::filesystem::path& file = command.scenes[i];
    const Scene& original = originals[i];
    if (!original.hierarchy)
      throw InputError(file.string() + ": precompute needs a \"hierarchy\" key (levels)");
    const double run_tolerance =
        command.tolerance > 0.0 ? command.tolerance : 0.5 * original.hierarchy->tolerance;
    std::vector<std::string> overrides = command.overrides;
    overrides.push_back("hierarchy.mode=\"adaptive\"");
    overrides.push_back("hierarchy.tolerance=" + json_number(run_tolerance));
    // The schedule records adaptive cuts, however large they grow.
    overrides.push_back("hierarchy.full_resolution_fraction=1");
    overrides.push_back("output.vtk=false");
    const Scene scene = load_scene(file, overrides);
    const PreparedMesh prepared = prepare_scene_mesh(scene);
    if (i == 0) {
      coarse = prepared.mesh;
      levels = scene.hierarchy->levels;
      tolerance = run_tolerance;
      first = file;
    } else {
      const Vector3d c0 = coarse.vertices.colwise().mean().transpose();
      const Vector3d c1 = prepared.mesh.vertices.colwise().mean().transpose();
      const double diagonal =
          (coarse.vertices.colwise().maxCoeff() - coarse.vertices.colwise().minCoeff()).norm();
      if (prepared.mesh.vertices.rows() != coarse.vertices.rows() ||
          prepared.mesh.tets.rows() != coarse.tets.rows() || (c1 - c0).norm() > 1e-9 * diagonal)
        throw InputError(file.string() + ": its mesh differs from that of " + first.string() +
                         " (a precomputed cut is made for one coarse mesh)");
      if (scene.hierarchy->levels != levels)
        throw InputError(file.string() +
                         ": hierarchy.levels = " + std::to_string(scene.hierarchy->levels) +
                         " differs from " + std::to_string(levels) + " of " + first.string());
      tolerance = std::min(tolerance, run_tolerance);
    }
    if (!command.quiet)
      log << "strata: precompute: run " << i + 1 << " of " << command.scenes.size() << ": "
          << file.string() << " (adaptive, tolerance " << run_tolerance << ")" << std::endl;
    recorder.add_source(scene.name);
    RunOptions options;
    options.output_dir = runs_dir / scene.name;
    options.quiet = true;
    options.progress = command.progress;
    options.log = &log;
    double run_end = 0.0;
    options.on_step = [&](const AdaptiveSimulation& run) {
      recorder.record(run.cut(), run.time());
      run_end = std::max(run_end, run.time());
    };
    const RunSummary summary = run_scene(scene, options);
    end = std::max(end, run_end);
    if (!command.quiet)
      log << "strata: precompute:   " << summary.steps << " steps in " << summary.wall_seconds
          << " s, " << recorder.num_refined() << " nodes refined so far; outputs in "
          << summary.output_dir.string() << std::endl;
  }

  const PrecomputedCut cut = recorder.schedule(command.windows, coarse, levels, tolerance, end);
  write_cut_file(command.output, cut);
  if (!command.quiet) {
    log << "strata: precompute: wrote " << command.output.string() << ": " << cut.windows.size()
        << (cut.windows.size() == 1 ? " window" : " windows") << " over [0, " << end
        << "], active tets";
    for (const CutWindow& window : cut.windows) {
      TetTree tree(coarse, levels);
      log << " " << cut_nodes(tree, window.refined).size();
    }
    log << " (coarse " << coarse.tets.rows() << ")" << std::endl;
  }
  if (!command.mesh.empty()) {
    TetTree tree(coarse, levels);
    ActiveCut active(tree, cut_nodes(tree, union_of_windows(cut)));
    const Index before = active.size();
    const ConformingMesh conforming = conforming_cut_mesh(active);
    write_tet_mesh(command.mesh, conforming.mesh);
    if (!command.quiet) {
      Index green = 0;
      for (Index t = 0; t < conforming.green.size(); ++t)
        green += conforming.green[t] > 0 ? 1 : 0;
      log << "strata: precompute: wrote " << command.mesh.string() << ": "
          << conforming.mesh.tets.rows() << " tets, " << conforming.mesh.vertices.rows()
          << " vertices (the cut's " << before << " tets, " << conforming.closure_refinements
          << " refined by the closure, " << green << " green tets)" << std::endl;
    }
  }
}

}  // namespace strata::app
