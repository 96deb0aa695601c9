// Compressed lists and the mesh adjacency built on them, against brute-force std::set versions.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "strata/core/common/compressed_lists.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

// Random lists with repeats: list i holds `length(i)` draws from [0, universe).
std::vector<std::vector<int>> random_lists(Index n, int universe, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> entry(0, universe - 1), length(0, 12);
  std::vector<std::vector<int>> lists(n);
  for (auto& list : lists) {
    list.resize(length(rng));
    for (int& value : list)
      value = entry(rng);
  }
  return lists;
}

void expect_lists_equal(const CompressedLists& actual,
                        const std::vector<std::vector<int>>& expected) {
  ASSERT_EQ(actual.size(), static_cast<Index>(expected.size()));
  ASSERT_EQ(actual.offsets.front(), 0);
  ASSERT_EQ(actual.offsets.back(), static_cast<Index>(actual.indices.size()));
  for (Index i = 0; i < actual.size(); ++i) {
    const auto list = actual[i];
    EXPECT_EQ(std::vector<int>(list.begin(), list.end()), expected[i]) << "list " << i;
  }
}

TEST(CompressedLists, SortedUniqueListsMatchSetsOnEveryThreadCount) {
  const Index n = 3000;
  const int universe = 400;
  const auto raw = random_lists(n, universe, 7);
  std::vector<std::vector<int>> expected;
  for (const auto& list : raw) {
    const std::set<int> unique(list.begin(), list.end());
    expected.emplace_back(unique.begin(), unique.end());
  }
  auto gather = [&](Index i, std::vector<int>& out) {
    out.insert(out.end(), raw[i].begin(), raw[i].end());
  };
  for (const int threads : {1, 2, 3}) {
    set_thread_policy({.threads = threads});
    SCOPED_TRACE(threads);
    expect_lists_equal(sorted_unique_lists(n, universe, gather), expected);
  }
  set_thread_policy({});
}

TEST(CompressedLists, EmptyAndOutOfRange) {
  const CompressedLists none = sorted_unique_lists(0, 5, [](Index, std::vector<int>&) {});
  EXPECT_EQ(none.size(), 0);
  EXPECT_TRUE(none.indices.empty());
  EXPECT_THROW(
      sorted_unique_lists(3, 5, [](Index i, std::vector<int>& out) { out.push_back(4 + i); }),
      std::logic_error);
}

TEST(CompressedLists, TransposeListsEveryMembershipOnce) {
  const Index n = 500;
  const int targets = 90;
  const auto raw = random_lists(n, targets, 11);
  CompressedLists lists;
  for (const auto& list : raw) {
    lists.indices.insert(lists.indices.end(), list.begin(), list.end());
    lists.offsets.push_back(static_cast<Index>(lists.indices.size()));
  }
  std::vector<std::vector<int>> expected(targets);
  for (Index i = 0; i < n; ++i)
    for (const int j : raw[i])
      expected[j].push_back(static_cast<int>(i));
  expect_lists_equal(transpose_lists(lists, targets), expected);
  EXPECT_THROW(transpose_lists(lists, targets - 1), std::logic_error);
}

TEST(CompressedLists, BlockPatternHoldsEveryBlockOnceAndZeros) {
  const Index n = 40;
  const auto raw = random_lists(n, static_cast<int>(n), 5);
  const CompressedLists lists = sorted_unique_lists(n, n, [&](Index i, std::vector<int>& out) {
    out.insert(out.end(), raw[i].begin(), raw[i].end());
  });
  const SparseMatrixd pattern = block_pattern(lists, "test matrix");
  // Reference: the same blocks through Eigen's triplet assembly.
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index b = 0; b < n; ++b)
    for (const int a : lists[b])
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          triplets.emplace_back(3 * a + i, 3 * b + j, 1.0);
  SparseMatrixd expected(3 * n, 3 * n);
  expected.setFromTriplets(triplets.begin(), triplets.end());
  ASSERT_TRUE(pattern.isCompressed());
  ASSERT_EQ(pattern.nonZeros(), expected.nonZeros());
  for (Index c = 0; c <= 3 * n; ++c)
    ASSERT_EQ(pattern.outerIndexPtr()[c], expected.outerIndexPtr()[c]) << "column " << c;
  for (Index k = 0; k < pattern.nonZeros(); ++k) {
    ASSERT_EQ(pattern.innerIndexPtr()[k], expected.innerIndexPtr()[k]) << "entry " << k;
    ASSERT_EQ(pattern.valuePtr()[k], 0.0);
  }
  for (Index b = 0; b < n; ++b)
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(block_column_start(lists, b, j), pattern.outerIndexPtr()[3 * b + j]);
}

// A box mesh with its vertices renumbered at random, so that adjacency is not banded.
TetMesh shuffled_box() {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(2, 1, 1.5), {5, 3, 4});
  std::vector<int> permutation(mesh.vertices.rows());
  for (std::size_t i = 0; i < permutation.size(); ++i)
    permutation[i] = static_cast<int>(i);
  std::shuffle(permutation.begin(), permutation.end(), std::mt19937(3));
  MatrixX3d vertices(mesh.vertices.rows(), 3);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    vertices.row(permutation[v]) = mesh.vertices.row(v);
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      mesh.tets(t, k) = permutation[mesh.tets(t, k)];
  mesh.vertices = vertices;
  return mesh;
}

TEST(MeshAdjacency, VertexTetsAndNeighboursMatchBruteForce) {
  const TetMesh mesh = shuffled_box();
  // One extra vertex in no tet: its lists are empty.
  const Index num_vertices = mesh.vertices.rows() + 1;
  std::vector<std::vector<int>> tets_of(num_vertices);
  std::vector<std::set<int>> neighbours(num_vertices);
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int a = 0; a < 4; ++a) {
      tets_of[mesh.tets(t, a)].push_back(static_cast<int>(t));
      for (int b = 0; b < 4; ++b)
        neighbours[mesh.tets(t, a)].insert(mesh.tets(t, b));
    }
  std::vector<std::vector<int>> expected_neighbours;
  for (const auto& set : neighbours)
    expected_neighbours.emplace_back(set.begin(), set.end());
  expect_lists_equal(vertex_tets(mesh.tets, num_vertices), tets_of);
  expect_lists_equal(vertex_neighbours(mesh.tets, num_vertices), expected_neighbours);
  EXPECT_THROW(vertex_tets(mesh.tets, num_vertices - 2), std::logic_error);
}

TEST(MeshAdjacency, BoundaryFacesAreTheUnmatchedFacesInSortedVertexOrder) {
  const TetMesh mesh = shuffled_box();
  // Reference: every face keyed by its sorted vertices; a key seen once is a boundary face, kept
  // with its tet's outward orientation, in key order.
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::map<std::array<int, 3>, std::vector<std::array<int, 3>>> by_key;
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (const auto& local : kFaces) {
      const std::array<int, 3> oriented = {mesh.tets(t, local[0]), mesh.tets(t, local[1]),
                                           mesh.tets(t, local[2])};
      std::array<int, 3> key = oriented;
      std::sort(key.begin(), key.end());
      by_key[key].push_back(oriented);
    }
  std::vector<std::array<int, 3>> expected;
  for (const auto& [key, faces] : by_key)
    if (faces.size() == 1) expected.push_back(faces.front());
  const MatrixX3i faces = boundary_faces(mesh.tets);
  ASSERT_EQ(faces.rows(), static_cast<Index>(expected.size()));
  for (Index f = 0; f < faces.rows(); ++f)
    EXPECT_EQ((std::array<int, 3>{faces(f, 0), faces(f, 1), faces(f, 2)}), expected[f])
        << "face " << f;
  MatrixX4i bad = mesh.tets;
  bad(3, 2) = -1;
  EXPECT_THROW(boundary_faces(bad), std::logic_error);
}

}  // namespace
}  // namespace strata
