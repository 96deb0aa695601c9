#include "strata/core/fem/tet_partition.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
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

/// Sorts (key, value) pairs by key, stably: least significant byte first, eight counting passes,
/// skipping the bytes in which all keys agree.
void stable_radix_sort(std::vector<std::pair<std::uint64_t, int>>& items) {
  std::vector<std::pair<std::uint64_t, int>> buffer(items.size());
  std::uint64_t all_or = 0, all_and = ~std::uint64_t{0};
  for (const auto& item : items) {
    all_or |= item.first;
    all_and &= item.first;
  }
  for (int shift = 0; shift < 64; shift += 8) {
    if ((((all_or ^ all_and) >> shift) & 0xff) == 0) continue;  // one value of this byte
    std::array<std::size_t, 257> start{};
    for (const auto& item : items)
      ++start[((item.first >> shift) & 0xff) + 1];
    for (int b = 0; b < 256; ++b)
      start[b + 1] += start[b];
    for (const auto& item : items)
      buffer[start[(item.first >> shift) & 0xff]++] = item;
    items.swap(buffer);
  }
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

  // Morton order of the tet centroids (no vertices: every tet is bad, and every key 0).
  const bool has_vertices = positions.rows() > 0;
  const Vector3d lower =
      has_vertices ? Vector3d(positions.colwise().minCoeff().transpose()) : Vector3d::Zero();
  const Vector3d extent =
      has_vertices ? Vector3d((positions.colwise().maxCoeff().transpose() - lower).cwiseMax(1e-300))
                   : Vector3d::Ones();
  // (code, tet) pairs, sorted by code; ties keep the tets' order (a stable sort from tet order).
  std::vector<std::pair<std::uint64_t, int>> keyed(num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index t) {
    Vector3d centroid = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      const int v = tets(t, k);
      if (v >= 0 && v < positions.rows()) centroid += positions.row(v).transpose();
    }
    const Vector3d unit = ((0.25 * centroid - lower).array() / extent.array()).matrix();
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      // NaN (a non-finite coordinate, which the rest data reports) goes to 0.
      const double u = unit[axis] > 0.0 ? std::min(unit[axis], 1.0) : 0.0;
      const auto cell = static_cast<std::uint64_t>(u * 2097151.0);
      key |= spread_bits(cell) << axis;
    }
    keyed[t] = {key, static_cast<int>(t)};
  });
  stable_radix_sort(keyed);
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

  // The vertices of each chunk (in parallel), then greedy colouring in chunk order: a chunk takes
  // the smallest colour that no earlier chunk sharing one of its vertices has. `taken[v]` holds
  // the colours of the chunks coloured so far that contain v, as bits (colours 64 and up in
  // further words).
  const Index num_vertices = positions.rows();
  std::vector<std::vector<int>> chunk_vertices(num_chunks);
  tbb::enumerable_thread_specific<std::vector<int>> stamps(
      [&] { return std::vector<int>(num_vertices, -1); });
  tbb::parallel_for(Index(0), num_chunks, [&](Index c) {
    std::vector<int>& stamp = stamps.local();
    std::vector<int>& vertices = chunk_vertices[c];
    for (int i = partition.chunk_begin[c]; i < partition.chunk_begin[c + 1]; ++i)
      for (int k = 0; k < 4; ++k) {
        const int v = tets(partition.order[i], k);
        if (v < 0 || v >= num_vertices || stamp[v] == c) continue;
        stamp[v] = static_cast<int>(c);
        vertices.push_back(v);
      }
  });
  Index words = 1;
  std::vector<std::uint64_t> taken(num_vertices, 0);
  std::vector<std::uint64_t> used;
  for (Index c = 0; c < num_chunks; ++c) {
    used.assign(words, 0);
    for (const int v : chunk_vertices[c])
      for (Index w = 0; w < words; ++w)
        used[w] |= taken[words * v + w];
    Index color = 0;
    while (color < 64 * words && (used[color / 64] >> (color % 64) & 1u) != 0)
      ++color;
    if (color == 64 * words) {  // every colour so far is taken: one more word per vertex
      std::vector<std::uint64_t> wider(num_vertices * (words + 1), 0);
      for (Index v = 0; v < num_vertices; ++v)
        std::copy_n(&taken[words * v], words, &wider[(words + 1) * v]);
      taken.swap(wider);
      ++words;
    }
    for (const int v : chunk_vertices[c])
      taken[words * v + color / 64] |= std::uint64_t{1} << (color % 64);
    if (color >= static_cast<Index>(partition.colors.size())) partition.colors.resize(color + 1);
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
