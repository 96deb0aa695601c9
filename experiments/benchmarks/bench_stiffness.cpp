// Stiffness assembly K = ∂²Ψ/∂x² into the model's fixed sparsity pattern, with and without
// per-element PSD projection: throughput in tets/s. Names:
// stiffness/<model>/<raw|psd>/tets:<#T>/threads:<n>.
#include <benchmark/benchmark.h>

#include <strata/core/common/parallel.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

void stiffness_benchmark(benchmark::State& state, MeshSize size, MaterialModel material,
                         bool project_psd, int threads) {
  const ThreadLimit limit(threads);
  const ModelCase& c = model_case(size, material);
  SparseMatrixd K;
  c.model->stiffness(c.deformed, K, project_psd);  // sets the pattern once, outside the timing
  for (auto _ : state) {
    c.model->stiffness(c.deformed, K, project_psd);
    benchmark::DoNotOptimize(K.valuePtr());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * c.model->num_tets());
  state.counters["tets"] = double(c.model->num_tets());
  state.counters["threads"] = threads;
  state.counters["nonzeros"] = double(K.nonZeros());
}

const bool registered = [] {
  for (const MeshSize& size : mesh_sizes())
    for (MaterialModel material : material_models())
      for (bool psd : {false, true})
        for (int threads : thread_counts())
          benchmark::RegisterBenchmark(
              benchmark_name("stiffness/" + to_string(material) + (psd ? "/psd" : "/raw"), size,
                             threads)
                  .c_str(),
              stiffness_benchmark, size, material, psd, threads)
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace strata::bench
