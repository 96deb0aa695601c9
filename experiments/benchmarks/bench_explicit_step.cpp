// A whole explicit time step (Simulation::advance: forces, damping, Dirichlet, ground, divergence
// and inversion checks, state bookkeeping) against the bare force evaluation it contains, on the
// same mesh, model and thread count: the box of bench_fixture clamped at x = 0 under gravity,
// dt = half the stable-step estimate. Report the ratio of items_per_second (explicit step over
// forces/<model>/… of bench_forces.cpp, measured back to back). Names:
// explicit_step/<integrator>/<model>/tets:<#T>/threads:<n>.
#include <benchmark/benchmark.h>

#include <memory>

#include <strata/core/common/parallel.hpp>
#include <strata/core/sim/simulation.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

void explicit_step_benchmark(benchmark::State& state, MeshSize size, MaterialModel material,
                             Integrator integrator, int threads) {
  set_thread_policy({.threads = threads});
  const TetMesh mesh = benchmark_mesh(size);
  DirichletSpec clamp;
  clamp.name = "fixed[0]";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  SolverSettings settings;
  settings.mode = SimulationMode::dynamic;
  settings.integrator = integrator;
  settings.dt = 1e-6;
  settings.duration = 1e3;
  {
    const Simulation probe(mesh,
                           {.material = benchmark_material(material),
                            .dirichlet = {clamp},
                            .gravity = Vector3d(0.0, 0.0, -9.81)},
                           settings);
    settings.dt = 0.5 * probe.stable_dt_estimate();
  }
  Simulation sim(mesh,
                 {.material = benchmark_material(material),
                  .dirichlet = {clamp},
                  .gravity = Vector3d(0.0, 0.0, -9.81)},
                 settings);
  sim.advance();  // warm-up
  const CpuSeconds cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    sim.advance();
    benchmark::DoNotOptimize(sim.positions().data());
  }
  // System over user CPU time of the timed steps (setup and first step excluded).
  state.counters["sys_per_user"] = system_share(cpu_start, process_cpu_seconds());
  state.SetItemsProcessed(state.iterations() * mesh.tets.rows());
  state.counters["tets"] = double(mesh.tets.rows());
  state.counters["threads"] = threads;
  state.counters["dt"] = settings.dt;
}

const bool registered = [] {
  for (const MeshSize& size : mesh_sizes())
    for (const Integrator integrator : {Integrator::symplectic_euler, Integrator::rk4})
      for (const MaterialModel material : {MaterialModel::stvk, MaterialModel::neohookean})
        for (int threads : thread_counts())
          benchmark::RegisterBenchmark(
              benchmark_name("explicit_step/" + to_string(integrator) + "/" + to_string(material),
                             size, threads)
                  .c_str(),
              explicit_step_benchmark, size, material, integrator, threads)
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace strata::bench
