// One backward-Euler step of a box built by the refinement tree — the coarse box (5 × 5 × 5
// cells, 750 tets, [0, 1]³ m) refined uniformly to level L: 48,000 / 384,000 / 3,072,000 tets —
// clamped at x = 0 under gravity, E = 1 MPa, ν = 0.45, ρ = 1000 kg/m³, dt = 1 ms, from rest,
// with each linear solver (CHOLMOD up to 384k tets; multigrid over the tree's levels). The first
// step (untimed) performs the symbolic analysis / first factorisation or multigrid setup; the
// timed steps follow it as consecutive steps of the running simulation (the box sags under
// gravity, so each step's matrices differ). Names:
// tree_implicit_euler_step/<solver>/tets:<#T>/threads:<n>.
// A second family, tree_implicit_euler_step_scaled_dt/multigrid/tets:<#T>/threads:<n>, runs the
// multigrid steps with dt = 1 ms · 2^(4−L), i.e. dt proportional to the edge length h. The Newton
// matrix M/dt² + K then keeps its balance of inertia (∝ ρh³/dt²) and stiffness (∝ Eh) across the
// sizes, which separates the multigrid's dependence on h from the change of the operator: at a
// fixed 1 ms the 48k box is inertia-dominated (ρh²/(E dt²) ≈ 2.5, h the cell size / 2^L) and the 3M
// box stiffness-dominated (≈ 0.16), and CG needs more iterations on the stiffer operator at any
// size.
//
// Counters: Newton iterations, CG iterations and multigrid setups per timed step, DOFs, levels, dt
// [ms], the wall time of all multigrid setups (the warm-up step's included) and of the warm-up
// step (first_step_seconds: with CHOLMOD its first factorisation).
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>

#include <strata/core/common/parallel.hpp>
#include <strata/core/fem/lumped_mass.hpp>
#include <strata/core/sim/dirichlet.hpp>
#include <strata/core/sim/implicit_euler.hpp>
#include <strata/core/sim/loads.hpp>
#include <strata/core/sim/problem.hpp>
#include <strata/core/sim/region.hpp>
#include <strata/hierarchy/active_cut.hpp>
#include <strata/hierarchy/cut_levels.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

struct TreeBox {
  std::unique_ptr<TetTree> tree;
  std::unique_ptr<ConstrainedCut> cut;
  NestedSpaces spaces;
  std::unique_ptr<ElasticModel> model;
  int level = -1;
};

const TreeBox& tree_box(int level) {
  static TreeBox box;
  if (box.level == level) return box;
  box = TreeBox{};
  box.tree =
      std::make_unique<TetTree>(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {5, 5, 5}), level);
  const ActiveCut cut = ActiveCut::uniform(*box.tree, level);
  box.cut = std::make_unique<ConstrainedCut>(flatten_cut(cut));
  box.spaces = cut_nested_spaces(*box.tree, *box.cut);
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.45;
  material.density = 1000.0;
  box.model = std::make_unique<ElasticModel>(box.cut->flat.mesh.vertices, box.cut->flat.mesh.tets,
                                             material);
  box.level = level;
  return box;
}

void tree_step_benchmark(benchmark::State& state, int level, LinearSolverKind solver, int threads,
                         double dt) {
  set_thread_policy({.threads = threads});
  const TreeBox& box = tree_box(level);
  const ElasticModel& model = *box.model;
  const TetMesh& mesh = box.cut->flat.mesh;
  const Material& mat = model.material();
  const VectorXd vertex_mass = lumped_vertex_mass(model.rest_data().rest_volume, model.tets(),
                                                  model.num_vertices(), mat.density);
  const VectorXd dof_mass = per_dof_mass(vertex_mass);
  const VectorXd f_ext = gravity_forces(vertex_mass, Vector3d(0.0, 0.0, -9.81));
  DirichletSpec clamp;
  clamp.name = "fixed[0]";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  const std::vector<DirichletGroup> groups =
      resolve_dirichlet_groups({clamp}, mesh.vertices, region_tolerance(mesh.vertices));
  const std::vector<char> constrained = dirichlet_dof_mask(groups, model.num_vertices());
  const EmbeddedElasticModel embedded(model);
  const Problem problem{.model = embedded,
                        .dof_mass = dof_mass,
                        .external_forces = f_ext,
                        .groups = groups,
                        .constrained = constrained,
                        .ramp_time = 1.0,
                        .diagonal = std::sqrt(3.0),
                        .nested_spaces = &box.spaces};
  SolverSettings settings;
  settings.dt = dt;
  ImplicitEuler stepper(problem, solver, newton_controls(settings, false));

  const VectorXd rest = model.rest_positions();
  VectorXd x = rest;
  VectorXd v = VectorXd::Zero(model.num_dofs());
  const auto warmup_start = std::chrono::steady_clock::now();
  stepper.step(0.0, settings.dt, x, v);  // warm-up: analysis / first setup
  const double warmup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - warmup_start).count();

  const long cg_start = stepper.linear_solver().cg_iterations();
  const long setups_start = stepper.linear_solver().multigrid_setups();
  long newton_iterations = 0;
  bool converged = true;
  double t = settings.dt;
  const CpuSeconds cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    const NewtonResult result = stepper.step(t, settings.dt, x, v);
    t += settings.dt;
    newton_iterations += result.iterations;
    converged = converged && result.converged;
    benchmark::DoNotOptimize(x.data());
  }
  // System over user CPU time of the timed steps (setup and first step excluded).
  state.counters["sys_per_user"] = system_share(cpu_start, process_cpu_seconds());
  const double n = double(state.iterations());
  state.SetItemsProcessed(state.iterations() * model.num_tets());
  state.counters["tets"] = double(model.num_tets());
  state.counters["dofs"] = double(model.num_dofs());
  state.counters["threads"] = threads;
  state.counters["dt_ms"] = dt * 1e3;
  state.counters["newton_iterations"] = double(newton_iterations) / n;
  state.counters["cg_iterations"] = double(stepper.linear_solver().cg_iterations() - cg_start) / n;
  state.counters["multigrid_setups"] =
      double(stepper.linear_solver().multigrid_setups() - setups_start) / n;
  state.counters["levels"] = stepper.linear_solver().multigrid_levels();
  // All multigrid setups of the run (Galerkin products, coarsest factorisation); the timed steps
  // added none when multigrid_setups = 0.
  state.counters["setup_seconds"] = stepper.linear_solver().multigrid_setup_seconds();
  state.counters["first_step_seconds"] = warmup_seconds;
  if (!converged) state.SkipWithError("Newton did not converge");
}

const bool registered = [] {
  // One step benchmark per family, solver, size and thread count.
  const auto add = [](const std::string& family, LinearSolverKind solver, int level, double dt) {
    const long long tets = 750LL << (3 * level);
    for (int threads : thread_counts()) {
      const std::string name = family + "/" + to_string(solver) + "/tets:" + std::to_string(tets) +
                               "/threads:" + std::to_string(threads);
      benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(
          name.c_str(), tree_step_benchmark, level, solver, threads, dt);
      b->Unit(benchmark::kMillisecond)->UseRealTime();
      b->Iterations(level >= 4 ? 2 : level == 3 ? 4 : 10);
    }
  };
  for (int level : {2, 3, 4})
    for (LinearSolverKind solver : {LinearSolverKind::cholmod, LinearSolverKind::multigrid})
      if (solver != LinearSolverKind::cholmod || level <= 3)
        add("tree_implicit_euler_step", solver, level, 1e-3);
  for (int level : {2, 3, 4})
    add("tree_implicit_euler_step_scaled_dt", LinearSolverKind::multigrid, level,
        1e-3 * (1 << (4 - level)));
  return true;
}();

}  // namespace
}  // namespace strata::bench
