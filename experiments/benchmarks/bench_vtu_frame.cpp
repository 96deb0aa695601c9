// Writing one binary (zlib-compressed) .vtu frame with the fields the CLI writes: displacement
// and velocity per vertex, Green strain, Cauchy stress, von Mises stress and level per tet.
// Throughput in tets/s and the raw array bytes per second (bytes_per_second) for each mesh size
// and thread count, and the file's size over the raw arrays' (file_over_raw); the fields are
// computed once, outside the timed loop. Names: vtu_frame/tets:<#T>/threads:<n>, and
// vtu_frame_series/… for the frames of a series between two cut changes, whose integer arrays
// (connectivity, offsets, types, level) come from the series' VtuArrayCache.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <strata/core/common/parallel.hpp>
#include <strata/core/io/vtu.hpp>

#include "bench_fixture.hpp"

namespace strata::bench {
namespace {

void vtu_frame_benchmark(benchmark::State& state, MeshSize size, int threads, bool series) {
  const ThreadLimit limit(threads);
  const ModelCase& c = model_case(size, MaterialModel::neohookean);
  const MatrixX3d positions = unflatten(c.deformed);
  const TetFields tet_fields = c.model->tet_fields(c.deformed);
  VtuFields fields;
  fields.add_point_data("displacement", Eigen::MatrixXd(positions - c.mesh.vertices));
  fields.add_point_data("velocity", Eigen::MatrixXd(positions - c.mesh.vertices));
  fields.add_cell_data("green_strain", Eigen::MatrixXd(tet_fields.green_strain));
  fields.add_cell_data("stress", Eigen::MatrixXd(tet_fields.cauchy_stress));
  fields.add_cell_data("von_mises", Eigen::MatrixXd(tet_fields.von_mises));
  fields.add_cell_data("level", Eigen::MatrixXi(Eigen::MatrixXi::Zero(c.mesh.tets.rows(), 1)));
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("strata_bench_frame_" + std::to_string(getpid()) + ".vtu");
  VtuArrayCache cache;
  if (series) write_vtu(path, positions, c.mesh.tets, fields, VtkEncoding::binary, &cache);
  for (auto _ : state)
    write_vtu(path, positions, c.mesh.tets, fields, VtkEncoding::binary, series ? &cache : nullptr);
  const double file_bytes = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
  const Index nv = c.mesh.vertices.rows(), nt = c.mesh.tets.rows();
  // Float64: 3 + 3 + 3 (points) per vertex, 6 + 6 + 1 per tet; Int32 level, Int64 connectivity
  // (4) and offsets (1), UInt8 type per tet.
  const double raw_bytes = 8.0 * (9 * nv + 13 * nt) + 4.0 * nt + 8.0 * 5 * nt + 1.0 * nt;
  state.SetItemsProcessed(state.iterations() * nt);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * raw_bytes));
  state.counters["tets"] = double(nt);
  state.counters["file_over_raw"] = file_bytes / raw_bytes;
  state.counters["threads"] = threads;
}

const bool registered = [] {
  for (const MeshSize& size : mesh_sizes())
    for (int threads : thread_counts())
      for (const bool series : {false, true})
        benchmark::RegisterBenchmark(
            benchmark_name(series ? "vtu_frame_series" : "vtu_frame", size, threads).c_str(),
            vtu_frame_benchmark, size, threads, series)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace strata::bench
