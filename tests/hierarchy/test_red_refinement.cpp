// Red refinement of one tet (Bey's rule): tiling, orientation, barycentric maps and shape quality
// over five levels, against an independent geometric computation of the children.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include "hierarchy/hierarchy_test_utils.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/hierarchy/red_refinement.hpp"
#include "strata/hierarchy/tet_tree.hpp"
#include "strata/hierarchy/uniform_refinement.hpp"

namespace strata {
namespace {

double signed_volume(const Matrix3x4d& x) {
  return tet_signed_volume(x.col(0), x.col(1), x.col(2), x.col(3));
}

Eigen::Vector4d barycentric(const Vector3d& p, const Matrix3x4d& x) {
  return tet_barycentric_coordinates(p, x.col(0), x.col(1), x.col(2), x.col(3));
}

std::vector<Matrix3x4d> test_tets() {
  Matrix3x4d negative = test::skinny_tet();
  negative.col(0).swap(negative.col(1));
  return {test::regular_tet(), test::kuhn_tet(), test::skinny_tet(), negative};
}

TEST(RedRefinement, ChildrenTileTheParent) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Matrix3x4d& parent : test_tets()) {
    const std::array<Matrix3x4d, 8> children = red_refine_tet(parent);
    const double parent_volume = signed_volume(parent);
    double sum = 0.0;
    for (int k = 0; k < 8; ++k) {
      const double volume = signed_volume(children[k]);
      // Red refinement halves every edge: each child has exactly an eighth of the volume.
      EXPECT_NEAR(std::abs(volume), std::abs(parent_volume) / 8, 1e-14 * std::abs(parent_volume));
      sum += std::abs(volume);
      for (int i = 0; i < 4; ++i) {
        const Eigen::Vector4d lambda = barycentric(children[k].col(i), parent);
        EXPECT_GE(lambda.minCoeff(), -1e-14) << "child " << k << " vertex " << i;
        // Child vertices are parent vertices (one λ = 1) or true edge midpoints (two λ = ½).
        for (int j = 0; j < 4; ++j) {
          const double snapped = std::round(2 * lambda[j]) / 2;
          EXPECT_NEAR(lambda[j], snapped, 1e-14);
        }
      }
    }
    EXPECT_NEAR(sum, std::abs(parent_volume), 1e-14 * std::abs(parent_volume));

    // Random points of the parent lie in exactly one child (no overlap, no gap).
    for (int sample = 0; sample < 2000; ++sample) {
      Eigen::Vector4d w(unit(rng), unit(rng), unit(rng), unit(rng));
      w = (-w.array().log()).matrix();  // uniform on the simplex
      w /= w.sum();
      const Vector3d p = parent * w;
      int containing = 0;
      for (const Matrix3x4d& child : children)
        if (barycentric(p, child).minCoeff() > 1e-12) ++containing;
      EXPECT_EQ(containing, 1) << "point " << p.transpose();
    }
  }
}

TEST(RedRefinement, OrientationTableMatchesGeometry) {
  for (const Matrix3x4d& parent : test_tets()) {
    const double parent_sign = signed_volume(parent) > 0 ? 1.0 : -1.0;
    const std::array<Matrix3x4d, 8> children = red_refine_tet(parent);
    for (int k = 0; k < 8; ++k)
      EXPECT_EQ(signed_volume(children[k]) > 0 ? 1.0 : -1.0, parent_sign * kBeyChildOrientation[k])
          << "child " << k;
  }
}

TEST(RedRefinement, TreeTetsArePositiveAtEveryLevel) {
  // Negatively ordered input too: the tree hands out positive tets regardless.
  for (const Matrix3x4d& root : test_tets()) {
    TetTree tree(test::single_tet_mesh(root), 4);
    refine_uniformly(tree, 4);
    const double root_volume = std::abs(signed_volume(root));
    for (NodeId n = 0; n < tree.pool_size(); ++n) {
      const double volume = signed_volume(tree.tet_positions(n));
      EXPECT_GT(volume, 0.0) << "node " << n;
      EXPECT_NEAR(volume, root_volume / std::pow(8.0, tree.level(n)), 1e-14 * root_volume);
      // The stored orientation is the sign of the Bey-ordered tet.
      EXPECT_EQ(signed_volume(tree.bey_positions(n)) > 0 ? 1 : -1, tree.node(n).orientation);
    }
  }
}

TEST(RedRefinement, BarycentricMapsAgreeWithGeometry) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-0.2, 1.2);
  const Matrix3x4d parent = test::skinny_tet();
  const std::array<Matrix3x4d, 8> children = red_refine_tet(parent);
  for (int sample = 0; sample < 200; ++sample) {
    const Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector4d lambda = barycentric(p, parent);
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector4d expected = barycentric(p, children[k]);
      const Eigen::Vector4d mapped = bey_child_barycentric_map(k) * lambda;
      EXPECT_LT((mapped - expected).cwiseAbs().maxCoeff(), 1e-11) << "child " << k;
    }
  }
}

struct LevelStatistics {
  std::vector<double> min_angle;  // [rad] per level
  std::size_t classes = 0;        // similarity classes over all levels, root included
};

LevelStatistics bey_statistics(const Matrix3x4d& root, int levels) {
  TetTree tree(test::single_tet_mesh(root), levels);
  refine_uniformly(tree, levels);
  LevelStatistics stats;
  stats.min_angle.assign(levels + 1, M_PI);
  std::set<std::array<long long, 6>> classes;
  for (NodeId n = 0; n < tree.pool_size(); ++n) {
    const Matrix3x4d x = tree.tet_positions(n);
    double& level_min = stats.min_angle[tree.level(n)];
    level_min = std::min(level_min, test::min_dihedral_angle(x));
    classes.insert(test::similarity_key(x));
  }
  stats.classes = classes.size();
  return stats;
}

// A naive alternative for comparison: corner tets as Bey's, the octahedron cut along its longest
// diagonal, computed independently of the library's tables.
std::array<Matrix3x4d, 8> refine_longest_diagonal(const Matrix3x4d& x) {
  const Eigen::Matrix<double, 3, 10> p = refinement_points(x);
  // Midpoint index (4 + edge) of the edge {a, b}.
  auto mid = [](int a, int b) {
    for (int e = 0; e < 6; ++e)
      if (kTetEdges[e][0] == std::min(a, b) && kTetEdges[e][1] == std::max(a, b)) return 4 + e;
    return -1;
  };
  std::array<Matrix3x4d, 8> children;
  for (int c = 0; c < 4; ++c) {
    children[c].col(0) = p.col(c);
    int i = 1;
    for (int other = 0; other < 4; ++other)
      if (other != c) children[c].col(i++) = p.col(mid(c, other));
  }
  // Diagonals join the midpoints of opposite edges e and 5 − e.
  int diagonal = 0;
  for (int e = 1; e < 3; ++e)
    if ((p.col(4 + e) - p.col(9 - e)).norm() > (p.col(4 + diagonal) - p.col(9 - diagonal)).norm())
      diagonal = e;
  const int a = kTetEdges[diagonal][0], b = kTetEdges[diagonal][1];
  const int c = kTetEdges[5 - diagonal][0], d = kTetEdges[5 - diagonal][1];
  const std::array<int, 4> equator{mid(a, c), mid(c, b), mid(b, d), mid(d, a)};
  for (int q = 0; q < 4; ++q) {
    children[4 + q].col(0) = p.col(4 + diagonal);
    children[4 + q].col(1) = p.col(9 - diagonal);
    children[4 + q].col(2) = p.col(equator[q]);
    children[4 + q].col(3) = p.col(equator[(q + 1) % 4]);
  }
  return children;
}

LevelStatistics longest_diagonal_statistics(const Matrix3x4d& root, int levels) {
  LevelStatistics stats;
  stats.min_angle.assign(levels + 1, M_PI);
  std::set<std::array<long long, 6>> classes{test::similarity_key(root)};
  stats.min_angle[0] = test::min_dihedral_angle(root);
  std::vector<Matrix3x4d> front{root};
  for (int level = 1; level <= levels; ++level) {
    std::vector<Matrix3x4d> next;
    for (const Matrix3x4d& x : front)
      for (const Matrix3x4d& child : refine_longest_diagonal(x)) {
        EXPECT_NEAR(std::abs(signed_volume(child)), std::abs(signed_volume(x)) / 8,
                    1e-13 * std::abs(signed_volume(x)));
        stats.min_angle[level] = std::min(stats.min_angle[level], test::min_dihedral_angle(child));
        classes.insert(test::similarity_key(child));
        next.push_back(child);
      }
    front.swap(next);
  }
  stats.classes = classes.size();
  return stats;
}

// Measured (degrees, minimum dihedral angle at levels 0..5 / classes):
//   Bey:      regular 70.5 54.7 54.7 54.7 54.7 54.7 / 2, Kuhn 45 at all levels / 1,
//             flat 24.5 9.0 9.0 9.0 9.0 9.0 / 3.
//   longest:  regular 70.5 54.7 35.3 25.2 13.3 9.4 / 17, Kuhn 45 35.3 18.4 15.8 7.1 5.8 / 32,
//             flat 24.5 9.0 9.0 4.5 3.7 1.5 / 63.
TEST(RedRefinement, BeyOrderingKeepsQualityOverFiveLevels) {
  const int levels = 5;
  for (const Matrix3x4d& root : {test::regular_tet(), test::kuhn_tet(), test::skinny_tet()}) {
    const LevelStatistics stats = bey_statistics(root, levels);
    for (int level = 3; level <= levels; ++level)
      EXPECT_GE(stats.min_angle[level], stats.min_angle[2] - 1e-12) << "level " << level;
    EXPECT_LE(stats.classes, 3u);  // Bey, Theorem 1
    EXPECT_GE(stats.classes, 1u);
  }
  // The Kuhn tet of the box mesh is ordered along its cube path: all descendants are congruent.
  EXPECT_EQ(bey_statistics(test::kuhn_tet(), levels).classes, 1u);
}

TEST(RedRefinement, LongestDiagonalDecays) {
  const int levels = 5;
  for (const Matrix3x4d& root : {test::regular_tet(), test::kuhn_tet(), test::skinny_tet()}) {
    const LevelStatistics naive = longest_diagonal_statistics(root, levels);
    const LevelStatistics bey = bey_statistics(root, levels);
    EXPECT_LT(naive.min_angle[levels], 0.5 * naive.min_angle[2]);
    EXPECT_LT(naive.min_angle[levels], 0.7 * bey.min_angle[levels]);
    EXPECT_GT(naive.classes, 3u);
  }
}

}  // namespace
}  // namespace strata
