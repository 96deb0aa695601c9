// The element schedule (tet_partition.hpp) against its definition: every tet once, chunks of whole
// lane groups, no two chunks of a colour sharing a vertex, and each chunk coloured greedily in
// chunk order (the smallest colour no earlier chunk sharing a vertex has).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "strata/core/fem/tet_partition.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

/// Morton codes of the tets' centroids in the mesh's bounding box, 21 bits per axis, x lowest.
std::vector<std::uint64_t> morton_codes(const MatrixX3d& vertices, const MatrixX4i& tets) {
  const Vector3d lower = vertices.colwise().minCoeff().transpose();
  const Vector3d extent = vertices.colwise().maxCoeff().transpose() - lower;
  std::vector<std::uint64_t> codes(static_cast<std::size_t>(tets.rows()), 0);
  for (Index t = 0; t < tets.rows(); ++t) {
    Vector3d centroid = Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      centroid += vertices.row(tets(t, k)).transpose();
    const Vector3d unit = ((0.25 * centroid - lower).array() / extent.array()).matrix();
    for (int axis = 0; axis < 3; ++axis) {
      const auto cell = static_cast<std::uint64_t>(std::clamp(unit[axis], 0.0, 1.0) * 2097151.0);
      for (int bit = 0; bit < 21; ++bit)
        codes[t] |= ((cell >> bit) & 1u) << (3 * bit + axis);
    }
  }
  return codes;
}

void expect_valid_schedule(const MatrixX3d& vertices, const MatrixX4i& tets, int target_chunks) {
  const TetPartition partition = build_tet_partition(vertices, tets, target_chunks);
  const Index num_tets = tets.rows();
  // Morton order of the centroids, ties in tet order.
  const std::vector<std::uint64_t> codes = morton_codes(vertices, tets);
  for (Index i = 1; i < num_tets; ++i) {
    const int a = partition.order[i - 1], b = partition.order[i];
    ASSERT_TRUE(codes[a] < codes[b] || (codes[a] == codes[b] && a < b)) << "position " << i;
  }
  // A permutation of the tets.
  std::vector<int> sorted = partition.order;
  std::sort(sorted.begin(), sorted.end());
  for (Index t = 0; t < num_tets; ++t)
    ASSERT_EQ(sorted[t], t);
  // Contiguous chunks from 0 to #T, each but the last starting at a multiple of 8.
  const Index num_chunks = partition.num_chunks();
  ASSERT_GE(num_chunks, 1);
  EXPECT_EQ(partition.chunk_begin.front(), 0);
  EXPECT_EQ(partition.chunk_begin.back(), num_tets);
  for (Index c = 0; c < num_chunks; ++c) {
    EXPECT_LT(partition.chunk_begin[c], partition.chunk_begin[c + 1]);
    EXPECT_EQ(partition.chunk_begin[c] % 8, 0);
  }
  // Vertices of each chunk; the colour of each chunk (each chunk in exactly one colour).
  std::vector<std::set<int>> chunk_vertices(num_chunks);
  for (Index c = 0; c < num_chunks; ++c)
    for (int i = partition.chunk_begin[c]; i < partition.chunk_begin[c + 1]; ++i)
      for (int k = 0; k < 4; ++k)
        chunk_vertices[c].insert(tets(partition.order[i], k));
  std::vector<int> color(num_chunks, -1);
  for (std::size_t k = 0; k < partition.colors.size(); ++k) {
    EXPECT_FALSE(partition.colors[k].empty());
    for (const int c : partition.colors[k]) {
      ASSERT_EQ(color[c], -1) << "chunk " << c << " in two colours";
      color[c] = static_cast<int>(k);
    }
  }
  const auto share = [&](Index a, Index b) {
    for (const int v : chunk_vertices[a])
      if (chunk_vertices[b].count(v)) return true;
    return false;
  };
  for (Index c = 0; c < num_chunks; ++c) {
    ASSERT_GE(color[c], 0) << "chunk " << c << " has no colour";
    std::set<int> used;
    for (Index j = 0; j < c; ++j)
      if (share(c, j)) used.insert(color[j]);
    int smallest = 0;
    while (used.count(smallest))
      ++smallest;
    EXPECT_EQ(color[c], smallest) << "chunk " << c;
    for (Index j = c + 1; j < num_chunks; ++j) {
      if (color[j] == color[c]) {
        EXPECT_FALSE(share(c, j)) << "chunks " << c << ", " << j;
      }
    }
  }
  // Chunks of one colour are listed in ascending order.
  for (const auto& chunks : partition.colors)
    EXPECT_TRUE(std::is_sorted(chunks.begin(), chunks.end()));
}

TEST(TetPartition, BoxMeshesAreScheduledAsDefined) {
  const TetMesh box = box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.0), {16, 8, 8});
  for (const int target : {1, 8, 64, 256})
    expect_valid_schedule(box.vertices, box.tets, target);
}

TEST(TetPartition, ShuffledTetsOfAThinMeshAreScheduledAsDefined) {
  // Tets in random order on a thin plate: many chunks meet at a vertex.
  const TetMesh plate = box_tet_mesh(Vector3d::Zero(), Vector3d(4.0, 4.0, 0.1), {40, 40, 1});
  MatrixX4i tets = plate.tets;
  std::vector<Index> order(static_cast<std::size_t>(tets.rows()));
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = static_cast<Index>(i);
  std::mt19937 random(7u);
  std::shuffle(order.begin(), order.end(), random);
  for (Index t = 0; t < tets.rows(); ++t)
    tets.row(t) = plate.tets.row(order[t]);
  expect_valid_schedule(plate.vertices, tets, 256);
}

TEST(TetPartition, MoreThan64ColoursAreScheduledAsDefined) {
  // A fan of 20,480 tets around one shared vertex: 80 chunks that all meet there need 80 colours,
  // more than one 64-bit word per vertex holds.
  const Index num_tets = 80 * 256;
  MatrixX3d vertices(1 + 3 * num_tets, 3);
  vertices.row(0).setZero();
  std::mt19937 random(11u);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Index v = 1; v < vertices.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      vertices(v, k) = uniform(random);
  MatrixX4i tets(num_tets, 4);
  for (Index t = 0; t < num_tets; ++t)
    tets.row(t) << 0, static_cast<int>(1 + 3 * t), static_cast<int>(2 + 3 * t),
        static_cast<int>(3 + 3 * t);
  EXPECT_EQ(build_tet_partition(vertices, tets, 256).colors.size(), 80u);
  expect_valid_schedule(vertices, tets, 256);
}

TEST(TetPartition, FewTetsMakeOneChunk) {
  const TetMesh box = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 2, 2});
  const TetPartition partition = build_tet_partition(box.vertices, box.tets, 256);
  EXPECT_EQ(partition.num_chunks(), 1);
  ASSERT_EQ(partition.colors.size(), 1u);
  expect_valid_schedule(box.vertices, box.tets, 256);
}

}  // namespace
}  // namespace strata
