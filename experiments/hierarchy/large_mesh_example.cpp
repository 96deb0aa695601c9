// strata_large_mesh_example: the hierarchy driven through the C++ API alone (no scene file) on a
// large coarse mesh — by default a 1 × 1 × 1.05 m box of 20 × 20 × 21 cells (50,400 coarse tets)
// with a three-level tree (25.8 million potential leaves), fixed at the bottom and pressed on a
// 0.1 × 0.1 m patch at the centre of the top face, run with backward Euler while the cut adapts.
//
// It prints, and writes as JSON to --out, the peak resident memory (VmHWM of /proc/self/status),
// the tree's memory_bytes against a lower bound for the full level-L tree, the active tets and
// DOFs after every step, the wall and CPU time per step, and the time spent in cut changes
// (bookkeeping). `--quick` runs a tiny case (a smoke test, a second or so).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/tree_size.hpp"

namespace {

using strata::Index;
using strata::Vector3d;
using Clock = std::chrono::steady_clock;

struct Options {
  std::array<int, 3> cells = {20, 20, 21};
  int levels = 3;
  int steps = 7;
  int adapt_every = 2;
  double dt = 5e-3;
  double threshold = 3.0;
  double force = 500.0;  ///< total downward force on the patch [N]
  std::string out;
  bool quick = false;
};

/// A /proc/self/status field in bytes (e.g. "VmHWM", "VmRSS"); 0 if unavailable.
std::uint64_t proc_status_bytes(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    return std::stoull(line.substr(key.size() + 1)) * 1024;  // the kernel reports kB
  }
  return 0;
}

/// Vertex, edge, face and tet counts of the full level-`levels` refinement of `mesh`: red
/// refinement adds a vertex per edge, splits edges in two, adds three edges per face and one per
/// tet (the octahedron's diagonal), and eight faces per tet:
///   V' = V + E,  E' = 2E + 3F + T,  F' = 4F + 8T,  T' = 8T.
std::array<double, 4> full_refinement_counts(const strata::TetMesh& mesh, int levels) {
  std::set<std::pair<int, int>> edges;
  std::set<std::array<int, 3>> faces;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    std::array<int, 4> v{mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
    std::sort(v.begin(), v.end());
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        edges.insert({v[a], v[b]});
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != skip) f[j++] = v[k];
      faces.insert(f);
    }
  }
  double V = double(mesh.vertices.rows()), E = double(edges.size()), F = double(faces.size()),
         T = double(mesh.tets.rows());
  for (int l = 0; l < levels; ++l) {
    const double V1 = V + E, E1 = 2 * E + 3 * F + T, F1 = 4 * F + 8 * T, T1 = 8 * T;
    V = V1, E = E1, F = F1, T = T1;
  }
  return {V, E, F, T};
}

/// A lower bound of TetTree::memory_bytes for the full tree: every node of every level (32 B) and
/// every vertex (position 24 B, parents 8 B, use count 4 B, level 1 B), plus 32 B per midpoint in
/// the hash table (16-byte slots, at most half full).
double full_tree_bytes_lower_bound(const strata::TetMesh& coarse, int levels) {
  double nodes = 0.0, per_level = double(coarse.tets.rows());
  for (int l = 0; l <= levels; ++l, per_level *= 8.0)
    nodes += per_level;
  const double vertices = full_refinement_counts(coarse, levels)[0];
  const double midpoints = vertices - double(coarse.vertices.rows());
  return nodes * sizeof(strata::TetNode) + vertices * (24 + 8 + 4 + 1) + midpoints * 32;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

int run(const Options& options) {
  const auto setup_start = Clock::now();
  const std::uint64_t rss_start = proc_status_bytes("VmRSS");
  const double h = 1.0 / options.cells[0];
  const Vector3d top(1.0, 1.0, h * options.cells[2]);
  const strata::TetMesh coarse = strata::box_tet_mesh(Vector3d::Zero(), top, options.cells);

  strata::HierarchySettings hierarchy;
  hierarchy.levels = options.levels;
  hierarchy.mode = strata::HierarchyMode::adaptive;
  hierarchy.level = 0;
  hierarchy.adapt_every = options.adapt_every;
  hierarchy.indicator = "force";
  hierarchy.criteria.refine_threshold = options.threshold;
  hierarchy.criteria.min_steps_between_changes = options.adapt_every;

  strata::Material material;
  material.model = strata::MaterialModel::neohookean;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;

  strata::DirichletSpec fixed;
  fixed.name = "fixed[0]";
  fixed.region = strata::PlaneRegion{Vector3d::Zero(), Vector3d::UnitZ(), 0.0};
  strata::RegionLoad press;
  press.name = "loads[0]";
  press.region = strata::BoxRegion{Vector3d(0.45, 0.45, top.z()), Vector3d(0.55, 0.55, top.z())};
  press.total_force = Vector3d(0.0, 0.0, -options.force);

  strata::SolverSettings solver;
  solver.mode = strata::SimulationMode::dynamic;
  solver.integrator = strata::Integrator::implicit_euler;
  solver.dt = options.dt;
  solver.duration = options.steps * options.dt;

  strata::AdaptiveSimulation simulation(
      coarse, hierarchy, {.material = material, .dirichlet = {fixed}, .loads = {press}}, solver);
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - setup_start).count();

  const std::uint64_t potential_leaves =
      strata::potential_leaf_count(std::uint64_t(coarse.tets.rows()), options.levels);
  const double full_bytes = full_tree_bytes_lower_bound(coarse, options.levels);
  std::cout << "coarse mesh: " << coarse.tets.rows() << " tets, " << coarse.vertices.rows()
            << " vertices; levels " << options.levels << " (" << potential_leaves
            << " potential leaves); setup " << setup_seconds << " s\n"
            << "full level-" << options.levels << " tree would need >= " << full_bytes / 1e6
            << " MB\n"
            << "step  time[s]  active_tets  dofs  step_s  cpu_s  tree_MB  rss_MB\n";

  nlohmann::json steps = nlohmann::json::array();
  std::size_t max_tree_bytes = simulation.tree().memory_bytes();
  std::vector<double> step_seconds;
  std::vector<double> step_cpu_seconds;  ///< process CPU time (all threads) per step
  while (!simulation.finished()) {
    const auto start = Clock::now();
    const std::clock_t cpu_start = std::clock();
    simulation.advance();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    const double cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    step_cpu_seconds.push_back(cpu_seconds);
    step_seconds.push_back(seconds);
    const std::size_t tree_bytes = simulation.tree().memory_bytes();
    max_tree_bytes = std::max(max_tree_bytes, tree_bytes);
    const strata::CutSample& sample = simulation.history().back();
    const std::uint64_t rss = proc_status_bytes("VmRSS");
    steps.push_back({{"step", sample.step},
                     {"time", sample.time},
                     {"active_tets", sample.tets},
                     {"dofs", sample.dofs},
                     {"seconds", seconds},
                     {"cpu_seconds", cpu_seconds},
                     {"tree_memory_bytes", tree_bytes},
                     {"rss_bytes", rss}});
    std::cout << sample.step << "  " << sample.time << "  " << sample.tets << "  " << sample.dofs
              << "  " << seconds << "  " << cpu_seconds << "  " << tree_bytes / 1e6 << "  "
              << rss / 1e6 << std::endl;
  }

  const double median = median_of(step_seconds);
  const double cpu_median = median_of(step_cpu_seconds);
  double total_step_seconds = 0.0;
  for (double s : step_seconds)
    total_step_seconds += s;
  const double bookkeeping = simulation.bookkeeping_seconds();
  const double stepping = simulation.stepping_seconds();
  const std::uint64_t peak = proc_status_bytes("VmHWM");
  const strata::SimulationCounters counters = simulation.counters();

  nlohmann::json report;
  report["coarse_tets"] = coarse.tets.rows();
  report["coarse_vertices"] = coarse.vertices.rows();
  report["levels"] = options.levels;
  report["potential_leaves"] = potential_leaves;
  report["full_tree_memory_bytes_lower_bound"] = full_bytes;
  report["tree_memory_bytes"] = simulation.tree().memory_bytes();
  report["max_tree_memory_bytes"] = max_tree_bytes;
  report["tree_nodes"] = simulation.tree().num_nodes();
  report["tree_vertices"] = simulation.tree().num_vertices();
  report["peak_memory_bytes"] = peak;
  report["rss_before_setup_bytes"] = rss_start;
  report["setup_seconds"] = setup_seconds;
  report["active_tets"] = simulation.cut().size();
  report["dofs"] = simulation.history().back().dofs;
  report["active_level_counts"] = simulation.cut().level_counts();
  report["median_step_seconds"] = median;
  report["median_step_cpu_seconds"] = cpu_median;
  report["mean_step_seconds"] =
      step_seconds.empty() ? 0.0 : total_step_seconds / double(step_seconds.size());
  report["bookkeeping_seconds"] = bookkeeping;
  report["stepping_seconds"] = stepping;
  report["bookkeeping_fraction"] =
      bookkeeping + stepping > 0.0 ? bookkeeping / (bookkeeping + stepping) : 0.0;
  report["cut_changes"] = simulation.changes().size();
  report["newton_iterations"] = counters.newton_iterations;
  report["dt"] = options.dt;
  report["steps"] = steps;

  std::cout << "active tets " << simulation.cut().size() << " of " << potential_leaves
            << " potential leaves; tree " << simulation.tree().memory_bytes() / 1e6 << " MB (max "
            << max_tree_bytes / 1e6 << " MB); peak memory " << peak / 1e6 << " MB\nmedian step "
            << median << " s; bookkeeping " << bookkeeping << " s of " << bookkeeping + stepping
            << " s (" << 100.0 * report["bookkeeping_fraction"].get<double>() << " %)\n";
  if (!options.out.empty()) {
    std::ofstream file(options.out);
    if (!file) throw strata::InputError("--out: cannot write " + options.out);
    file << report.dump(2) << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"strata_large_mesh_example: an adaptive hierarchy on a large coarse mesh"};
  Options options;
  app.add_option("--cells", options.cells, "box cells (6 tets each)");
  app.add_option("--levels", options.levels, "levels of the tree below the coarse mesh");
  app.add_option("--steps", options.steps, "backward-Euler steps");
  app.add_option("--adapt-every", options.adapt_every, "steps between two adaptations");
  app.add_option("--dt", options.dt, "time step [s]");
  app.add_option("--threshold", options.threshold, "refine threshold of the force indicator");
  app.add_option("--force", options.force, "total force on the patch [N]");
  app.add_option("--out", options.out, "JSON report");
  app.add_flag("--quick", options.quick, "a tiny run (4 x 4 x 4 cells, 2 levels, 4 steps)");
  CLI11_PARSE(app, argc, argv);
  if (options.quick) {
    options.cells = {4, 4, 4};
    options.levels = 2;
    options.steps = 4;
    options.adapt_every = 2;
  }
  try {
    return run(options);
  } catch (const strata::InputError& error) {
    std::cerr << "strata_large_mesh_example: error: " << error.what() << "\n";
    return 2;
  } catch (const strata::DivergenceError& error) {
    std::cerr << "strata_large_mesh_example: error: " << error.what() << "\n";
    return 3;
  }
}
