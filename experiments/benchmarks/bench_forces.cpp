// Internal-force evaluation f = −∂Ψ/∂x and the elastic energy Ψ alone: throughput in tets/s
// (items_per_second) for each material model, mesh size and thread count. Names:
// forces/<model>/tets:<#T>/threads:<n> and energy/<model>/tets:<#T>/threads:<n>.
#include <benchmark/benchmark.h>

#include <strata/core/common/parallel.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

/// One evaluation per iteration: the forces (`energy` false) or the energy alone.
void evaluation_benchmark(benchmark::State& state, MeshSize size, MaterialModel material,
                          int threads, bool energy) {
  const ThreadLimit limit(threads);
  const ModelCase& c = model_case(size, material);
  VectorXd f(c.model->num_dofs());
  for (auto _ : state) {
    if (energy) {
      benchmark::DoNotOptimize(c.model->energy(c.deformed));
    } else {
      c.model->forces(c.deformed, f);
      benchmark::DoNotOptimize(f.data());
      benchmark::ClobberMemory();
    }
  }
  state.SetItemsProcessed(state.iterations() * c.model->num_tets());
  state.counters["tets"] = double(c.model->num_tets());
  state.counters["threads"] = threads;
}

const bool registered = [] {
  for (const bool energy : {false, true})
    for (const MeshSize& size : mesh_sizes())
      for (MaterialModel material : material_models())
        for (int threads : thread_counts())
          benchmark::RegisterBenchmark(
              benchmark_name((energy ? "energy/" : "forces/") + to_string(material), size, threads)
                  .c_str(),
              evaluation_benchmark, size, material, threads, energy)
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace strata::bench
