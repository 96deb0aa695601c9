#include "strata/core/fem/tet_partition.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace strata {

namespace {

/// Spreads the low 21 bits of v so that two zero bits separate consecutive bits.
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

TetPartition build_tet_partition(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 int target_chunks) {
  TetPartition partition;
  const Index num_tets = tets.rows();
  partition.order.resize(num_tets);
  std::iota(partition.order.begin(), partition.order.end(), 0);
  if (num_tets == 0) {
    partition.chunk_begin = {0};
    return partition;
  }

  // Morton order of the tet centroids.
  const Vector3d lower = positions.colwise().minCoeff().transpose();
  const Vector3d extent = (positions.colwise().maxCoeff().transpose() - lower).cwiseMax(1e-300);
  // (code, tet) pairs: sorting them orders ties by tet index, as a stable sort by code would.
  std::vector<std::pair<std::uint64_t, int>> keyed(num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index t) {
    Vector3d centroid = Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      centroid += positions.row(tets(t, k)).transpose();
    const Vector3d unit = ((0.25 * centroid - lower).array() / extent.array()).matrix();
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto cell = static_cast<std::uint64_t>(std::clamp(unit[axis], 0.0, 1.0) * 2097151.0);
      key |= spread_bits(cell) << axis;
    }
    keyed[t] = {key, static_cast<int>(t)};
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  for (Index i = 0; i < num_tets; ++i)
    partition.order[i] = keyed[i].second;

  // Contiguous chunks of at least 256 tets, a multiple of 8 so that vectorised kernels see whole
  // lane groups (all chunks but the last).
  Index chunk_size =
      std::max<Index>(256, (num_tets + target_chunks - 1) / std::max(1, target_chunks));
  chunk_size = (chunk_size + 7) / 8 * 8;
  for (Index begin = 0; begin < num_tets; begin += chunk_size)
    partition.chunk_begin.push_back(static_cast<int>(begin));
  partition.chunk_begin.push_back(static_cast<int>(num_tets));
  const Index num_chunks = partition.num_chunks();

  // Chunks touching each vertex (compressed lists, ascending), then greedy colouring in chunk
  // order. `seen[v] == c` marks vertex v as visited for chunk c.
  const Index num_vertices = positions.rows();
  std::vector<int> seen(num_vertices, -1);
  std::vector<int> start(num_vertices + 1, 0);
  const auto for_each_chunk_vertex = [&](Index c, auto&& body) {
    for (int i = partition.chunk_begin[c]; i < partition.chunk_begin[c + 1]; ++i)
      for (int k = 0; k < 4; ++k) {
        const int v = tets(partition.order[i], k);
        if (seen[v] == c) continue;
        seen[v] = static_cast<int>(c);
        body(v);
      }
  };
  for (Index c = 0; c < num_chunks; ++c)
    for_each_chunk_vertex(c, [&](int v) { ++start[v + 1]; });
  for (Index v = 0; v < num_vertices; ++v)
    start[v + 1] += start[v];
  std::vector<int> vertex_chunks(start[num_vertices]);
  std::vector<int> next(start.begin(), start.end() - 1);
  seen.assign(num_vertices, -1);
  for (Index c = 0; c < num_chunks; ++c)
    for_each_chunk_vertex(c, [&](int v) { vertex_chunks[next[v]++] = static_cast<int>(c); });

  std::vector<int> chunk_color(num_chunks, -1);
  std::vector<char> used;
  seen.assign(num_vertices, -1);
  for (Index c = 0; c < num_chunks; ++c) {
    used.assign(num_chunks + 1, 0);
    for_each_chunk_vertex(c, [&](int v) {
      for (int j = start[v]; j < start[v + 1]; ++j)
        if (chunk_color[vertex_chunks[j]] >= 0) used[chunk_color[vertex_chunks[j]]] = 1;
    });
    int color = 0;
    while (used[color])
      ++color;
    chunk_color[c] = color;
    if (color >= static_cast<int>(partition.colors.size())) partition.colors.resize(color + 1);
    partition.colors[color].push_back(static_cast<int>(c));
  }
  return partition;
}

void for_each_chunk_colored(const TetPartition& partition, const std::function<void(int)>& body) {
  for (const auto& chunks : partition.colors) {
    if (chunks.size() == 1) {
      body(chunks.front());
      continue;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          body(chunks[i]);
                      });
  }
}

}  // namespace strata
