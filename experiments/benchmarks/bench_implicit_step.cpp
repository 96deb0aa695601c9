// One backward-Euler step (ImplicitEuler, Newton + CHOLMOD, or CG with hypre's algebraic
// multigrid) of a box clamped at x = 0 under gravity, starting from rest each time: wall time per
// step and tets/s. The symbolic analysis of the linear solver (or the first AMG hierarchy) happens
// in an untimed warm-up step; the timed steps reuse it like a running simulation. Threads follow
// strata's process policy (TBB at <n>, CHOLMOD's BLAS and OpenMP at 1; hypre runs on one).
// Names: implicit_euler_step/<model>/tets:<#T>/threads:<n> (CHOLMOD) and
// implicit_euler_step/<model>/solver:amg/tets:<#T>/threads:<n> (StVK only).
#include <benchmark/benchmark.h>

#include <chrono>

#include <strata/core/common/parallel.hpp>
#include <strata/core/fem/lumped_mass.hpp>
#include <strata/core/sim/dirichlet.hpp>
#include <strata/core/sim/implicit_euler.hpp>
#include <strata/core/sim/loads.hpp>
#include <strata/core/sim/problem.hpp>
#include <strata/core/sim/region.hpp>
#include <strata/core/sim/solver_settings.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

void implicit_step_benchmark(benchmark::State& state, MeshSize size, MaterialModel material,
                             int threads, LinearSolverKind solver) {
  set_thread_policy({.threads = threads});
  const ModelCase& c = model_case(size, material);
  const ElasticModel& model = *c.model;
  const Material& mat = model.material();

  const VectorXd vertex_mass = lumped_vertex_mass(model.rest_data().rest_volume, model.tets(),
                                                  model.num_vertices(), mat.density);
  const VectorXd dof_mass = per_dof_mass(vertex_mass);
  const VectorXd f_ext = gravity_forces(vertex_mass, Vector3d(0.0, 0.0, -9.81));

  const double tolerance = region_tolerance(c.mesh.vertices);
  DirichletSpec clamp;
  clamp.name = "fixed[0]";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  const std::vector<DirichletGroup> groups =
      resolve_dirichlet_groups({clamp}, c.mesh.vertices, tolerance);
  const std::vector<char> constrained = dirichlet_dof_mask(groups, model.num_vertices());
  const auto [lo, hi] = bounding_box(c.mesh.vertices);

  const SolverSettings settings;
  const EmbeddedElasticModel embedded(model);
  const Problem problem{.model = embedded,
                        .dof_mass = dof_mass,
                        .external_forces = f_ext,
                        .groups = groups,
                        .constrained = constrained,
                        .mass_damping = mat.mass_damping,
                        .stiffness_damping = mat.stiffness_damping,
                        .ramp_time = 1.0,
                        .diagonal = (hi - lo).norm()};
  ImplicitEuler stepper(problem, solver, newton_controls(settings, false));

  const VectorXd rest = model.rest_positions();
  VectorXd x = rest;
  VectorXd v = VectorXd::Zero(model.num_dofs());
  // Warm-up: symbolic analysis and first factorisation, or the first multigrid setup.
  const auto warm_up_start = std::chrono::steady_clock::now();
  stepper.step(0.0, settings.dt, x, v);
  const double warm_up_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - warm_up_start).count();

  const long cg_start = stepper.linear_solver().cg_iterations();
  const long setups_start = stepper.linear_solver().multigrid_setups();
  long newton_iterations = 0;
  bool converged = true;
  const CpuSeconds cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    x = rest;
    v.setZero();
    const NewtonResult result = stepper.step(0.0, settings.dt, x, v);
    newton_iterations += result.iterations;
    converged = converged && result.converged;
    benchmark::DoNotOptimize(x.data());
  }
  // System over user CPU time of the timed steps (setup and first step excluded).
  state.counters["sys_per_user"] = system_share(cpu_start, process_cpu_seconds());
  state.SetItemsProcessed(state.iterations() * model.num_tets());
  state.counters["tets"] = double(model.num_tets());
  state.counters["threads"] = threads;
  state.counters["dofs"] = double(model.num_dofs());
  state.counters["newton_iterations"] = double(newton_iterations) / double(state.iterations());
  state.counters["dt"] = settings.dt;
  state.counters["first_step_s"] = warm_up_seconds;
  const double n = double(state.iterations());
  state.counters["cg_iterations"] = double(stepper.linear_solver().cg_iterations() - cg_start) / n;
  state.counters["amg_setups"] =
      double(stepper.linear_solver().multigrid_setups() - setups_start) / n;
  if (!converged) state.SkipWithError("Newton did not converge");
}

const bool registered = [] {
  for (const MeshSize& size : mesh_sizes())
    for (MaterialModel material : material_models())
      for (int threads : thread_counts())
        for (LinearSolverKind solver : {LinearSolverKind::cholmod, LinearSolverKind::amg}) {
          if (solver == LinearSolverKind::amg && material != MaterialModel::stvk) continue;
          const std::string prefix = "implicit_euler_step/" + to_string(material) +
                                     (solver == LinearSolverKind::amg ? "/solver:amg" : "");
          benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(
              benchmark_name(prefix, size, threads).c_str(), implicit_step_benchmark, size,
              material, threads, solver);
          b->Unit(benchmark::kMillisecond)->UseRealTime();
          if (size.num_tets() > 100000) b->Iterations(1);
        }
  return true;
}();

}  // namespace
}  // namespace strata::bench
