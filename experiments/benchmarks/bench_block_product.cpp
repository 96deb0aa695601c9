// The product y = K x of a stiffness matrix stored by 3 × 3 blocks (BlockSymmetricMatrix), with
// its values in double (CG's products) and rounded to single precision (the multigrid cycle's,
// MultigridOptions::single_precision_min_blocks), and the copy from the compressed matrix (assign)
// without and with the rounded values, which a Newton iteration pays. Bytes per second count
// the values, block rows and x and y as read or written once. Names:
// block_product/<double|single|assign|assign_single>/tets:<#T>/threads:<n>.
#include <benchmark/benchmark.h>

#include <string>

#include <strata/core/common/parallel.hpp>
#include <strata/core/sim/block_matrix.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

enum class Operation { double_product, single_product, assign, assign_single };

void block_product_benchmark(benchmark::State& state, MeshSize size, Operation operation,
                             int threads) {
  const ThreadLimit limit(threads);
  const ModelCase& c = model_case(size, MaterialModel::neohookean);
  SparseMatrixd K;
  c.model->stiffness(c.deformed, K, false);
  BlockSymmetricMatrix blocks;
  blocks.keep_single_precision(operation != Operation::assign);
  if (!blocks.assign(K)) {
    state.SkipWithError("the stiffness pattern has no whole 3 x 3 blocks");
    return;
  }
  const VectorXd x = c.deformed;
  VectorXd y(x.size());
  const double num_blocks = double(K.nonZeros()) / 9.0;
  for (auto _ : state) {
    switch (operation) {
      case Operation::double_product:
        blocks.multiply(x, y);
        break;
      case Operation::single_product:
        blocks.multiply_single(x, y, {});
        break;
      case Operation::assign:
      case Operation::assign_single:
        blocks.assign(K);
        break;
    }
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  double bytes = 0.0;
  if (operation == Operation::double_product || operation == Operation::single_product)
    bytes = num_blocks * (9.0 * (operation == Operation::double_product ? 8.0 : 4.0) + 4.0) +
            16.0 * double(x.size());
  else  // read the values and row indices, write the values (and the rounded ones)
    bytes =
        num_blocks * (9.0 * (8.0 + 4.0 + 8.0 + (operation == Operation::assign ? 0.0 : 4.0)) + 4.0);
  state.SetBytesProcessed(static_cast<std::int64_t>(double(state.iterations()) * bytes));
  state.counters["tets"] = double(c.model->num_tets());
  state.counters["threads"] = threads;
  state.counters["blocks"] = num_blocks;
}

const bool registered = [] {
  const std::pair<Operation, const char*> operations[] = {
      {Operation::double_product, "double"},
      {Operation::single_product, "single"},
      {Operation::assign, "assign"},
      {Operation::assign_single, "assign_single"}};
  for (const MeshSize& size : mesh_sizes())
    for (const auto& [operation, name] : operations)
      for (int threads : thread_counts())
        benchmark::RegisterBenchmark(
            benchmark_name(std::string("block_product/") + name, size, threads).c_str(),
            block_product_benchmark, size, operation, threads)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace strata::bench
