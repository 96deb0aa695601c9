// The same scene at full resolution and adaptive (AdaptiveSimulation, strata::hierarchy): a
// 1 × 1 × 0.25 m neo-Hookean slab of 8 × 8 × 2 coarse cells (768 coarse tets, two tree levels:
// 49,152 tets at full resolution) fixed at the bottom and pressed by a 0.2 × 0.2 m patch on top
// (the geometry of experiments/scenes/slab_press.json).
//   - hierarchy_static/<mode>: the static run of slab_press (2 load steps, stress-jump indicator,
//     threshold 0.15, up to 8 solve–mark–refine passes per load step); one iteration = the whole
//     run; time per load step reported.
//   - hierarchy_implicit_euler/<mode>: backward Euler (dt = 2 ms, the cut adapted every 5 steps);
//     warm-up steps (untimed) let the cut settle, then one iteration = one time step. Reported for
//     the adaptive run: the bookkeeping fraction in that steady state,
//     Δbookkeeping_seconds / (Δbookkeeping_seconds + Δstepping_seconds) over the timed steps,
//     and the mean cut change against the mean step (change_per_step: wall time of one change
//     over the stepping time of one step, both from the timed steps; change_per_step_whole: the
//     same with the multigrid setups made on the change's cut added to the change, which the
//     steps include).
// Counters: active tets and DOFs at the end, seconds per step, cut changes, bookkeeping fraction.
#include <benchmark/benchmark.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <strata/core/mesh/tet_mesh.hpp>
#include <strata/hierarchy/adaptive_simulation.hpp>

namespace strata::bench {
namespace {

/// Implicit Euler: untimed steps before the timed ones (full: the first factorisation only).
long warmup_steps(HierarchyMode mode) {
  return mode == HierarchyMode::full ? 1 : 20;
}

struct SlabScene {
  TetMesh coarse;
  Material material;
  DirichletSpec fixed;
  RegionLoad press;
};

SlabScene slab_scene() {
  SlabScene scene;
  scene.coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 0.25), {8, 8, 2});
  scene.material.model = MaterialModel::neohookean;
  scene.material.youngs_modulus = 1e6;
  scene.material.poisson_ratio = 0.3;
  scene.material.density = 1000.0;
  scene.fixed.name = "fixed[0]";
  scene.fixed.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitZ(), 0.0};
  scene.press.name = "forces[0]";
  scene.press.region = BoxRegion{Vector3d(0.4, 0.4, 0.25), Vector3d(0.6, 0.6, 0.25)};
  scene.press.total_force = Vector3d(0.0, 0.0, -500.0);
  return scene;
}

HierarchySettings slab_hierarchy(HierarchyMode mode) {
  HierarchySettings hierarchy;
  hierarchy.levels = 2;
  hierarchy.mode = mode;
  hierarchy.level = 0;
  hierarchy.indicator = "stress_jump";
  hierarchy.criteria.refine_threshold = 0.15;
  hierarchy.max_passes = 8;
  hierarchy.adapt_every = 5;
  hierarchy.criteria.min_steps_between_changes = 5;
  return hierarchy;
}

std::unique_ptr<AdaptiveSimulation> make_simulation(HierarchyMode mode,
                                                    const SolverSettings& solver) {
  const SlabScene scene = slab_scene();
  return std::make_unique<AdaptiveSimulation>(
      scene.coarse, slab_hierarchy(mode),
      ProblemSpec{.material = scene.material,
                  .dirichlet = std::vector<DirichletSpec>{scene.fixed},
                  .loads = std::vector<RegionLoad>{scene.press}},
      solver);
}

void report_cut(benchmark::State& state, const AdaptiveSimulation& simulation) {
  const CutSample& sample = simulation.history().back();
  state.counters["tets"] = double(sample.tets);
  state.counters["dofs"] = double(sample.dofs);
  state.counters["cut_changes"] = double(simulation.changes().size());
}

void static_benchmark(benchmark::State& state, HierarchyMode mode) {
  SolverSettings solver;
  solver.mode = SimulationMode::static_equilibrium;
  solver.load_steps = 2;
  double bookkeeping = 0.0, stepping = 0.0;
  long steps = 0;
  std::unique_ptr<AdaptiveSimulation> simulation;
  for (auto _ : state) {
    simulation = make_simulation(mode, solver);
    while (!simulation->finished())
      simulation->advance();
    steps += simulation->step_count();
    bookkeeping += simulation->bookkeeping_seconds();
    stepping += simulation->stepping_seconds();
  }
  report_cut(state, *simulation);
  state.counters["seconds_per_step"] = (bookkeeping + stepping) / double(steps);
  state.counters["bookkeeping_fraction"] = bookkeeping / (bookkeeping + stepping);
}

void implicit_euler_benchmark(benchmark::State& state, HierarchyMode mode) {
  SolverSettings solver;
  solver.integrator = Integrator::implicit_euler;
  solver.dt = 2e-3;
  solver.duration = 1.0;  // never reached: the benchmark stops first
  std::unique_ptr<AdaptiveSimulation> simulation = make_simulation(mode, solver);
  for (long k = 0; k < warmup_steps(mode); ++k)
    simulation->advance();
  const double bookkeeping_start = simulation->bookkeeping_seconds();
  const double stepping_start = simulation->stepping_seconds();
  const std::size_t changes_start = simulation->changes().size();
  for (auto _ : state)
    simulation->advance();
  const double bookkeeping = simulation->bookkeeping_seconds() - bookkeeping_start;
  const double stepping = simulation->stepping_seconds() - stepping_start;
  report_cut(state, *simulation);
  const std::size_t timed_changes = simulation->changes().size() - changes_start;
  state.counters["timed_cut_changes"] = double(timed_changes);
  if (timed_changes > 0) {
    double change_seconds = 0.0, setup_seconds = 0.0;
    for (std::size_t k = changes_start; k < simulation->changes().size(); ++k) {
      change_seconds += simulation->changes()[k].seconds;
      setup_seconds += simulation->changes()[k].multigrid_setup_seconds;
    }
    const double step_seconds = stepping / double(state.iterations());
    state.counters["change_per_step"] = (change_seconds / double(timed_changes)) / step_seconds;
    state.counters["change_per_step_whole"] =
        ((change_seconds + setup_seconds) / double(timed_changes)) / step_seconds;
  }
  state.counters["seconds_per_step"] = (bookkeeping + stepping) / double(state.iterations());
  state.counters["bookkeeping_fraction"] = bookkeeping / (bookkeeping + stepping);
}

const bool registered = [] {
  for (HierarchyMode mode : {HierarchyMode::full, HierarchyMode::adaptive}) {
    benchmark::RegisterBenchmark(("hierarchy_static/slab_press/" + to_string(mode)).c_str(),
                                 static_benchmark, mode)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(1);
    // 10 timed steps: two adaptations of the adaptive run.
    benchmark::RegisterBenchmark(("hierarchy_implicit_euler/slab_press/" + to_string(mode)).c_str(),
                                 implicit_euler_benchmark, mode)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(mode == HierarchyMode::full ? 3 : 10);
  }
  return true;
}();

}  // namespace
}  // namespace strata::bench
