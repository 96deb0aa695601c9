// Point location through the tree, checked against brute force over all leaves and against the
// barycentric identity Σ λ_i x_i = p.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "hierarchy/hierarchy_test_utils.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/hierarchy/tree_point_location.hpp"

namespace strata {
namespace {

// A tree refined irregularly (random leaves, up to level 4) over a box with a negatively ordered
// root, so both orientations are exercised.
TetTree random_tree(std::mt19937& rng) {
  TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 2.0, 1.0), {2, 3, 2});
  coarse.tets.row(4).tail<2>() = coarse.tets.row(4).tail<2>().reverse().eval();
  TetTree tree(coarse, 4);
  for (int step = 0; step < 120; ++step) {
    const std::vector<NodeId> leaves = tree.leaves();
    std::uniform_int_distribution<std::size_t> pick(0, leaves.size() - 1);
    const NodeId n = leaves[pick(rng)];
    if (tree.can_refine(n)) tree.refine(n);
  }
  return tree;
}

Eigen::Vector4d barycentric(const Vector3d& p, const Matrix3x4d& x) {
  return tet_barycentric_coordinates(p, x.col(0), x.col(1), x.col(2), x.col(3));
}

TEST(TreePointLocation, MatchesBruteForceOverLeaves) {
  std::mt19937 rng(2);
  const TetTree tree = random_tree(rng);
  EXPECT_LT(tree.node(4).orientation, 0);
  const TreePointLocator locator(tree);
  const std::vector<NodeId> leaves = tree.leaves();
  std::uniform_real_distribution<double> x(0.0, 1.0), y(0.0, 2.0);
  for (int sample = 0; sample < 300; ++sample) {
    const Vector3d p(x(rng), y(rng), x(rng));
    const std::optional<TreeLocation> found = locator.locate(tree, p, 0.0);
    ASSERT_TRUE(found) << p.transpose();
    EXPECT_TRUE(tree.is_leaf(found->node));
    const Matrix3x4d xs = tree.tet_positions(found->node);
    EXPECT_NEAR(found->barycentric.sum(), 1.0, 1e-14);
    EXPECT_LT((xs * found->barycentric - p).norm(), 1e-14);
    EXPECT_GE(found->barycentric.minCoeff(), -1e-12);

    // Brute force: every leaf that contains p (several when p is on a shared face).
    std::vector<NodeId> containing;
    for (const NodeId leaf : leaves)
      if (barycentric(p, tree.tet_positions(leaf)).minCoeff() >= -1e-12) containing.push_back(leaf);
    ASSERT_FALSE(containing.empty());
    EXPECT_NE(std::find(containing.begin(), containing.end(), found->node), containing.end());
  }
}

TEST(TreePointLocation, StopsAtARequestedLevel) {
  std::mt19937 rng(4);
  const TetTree tree = random_tree(rng);
  const TreePointLocator locator(tree);
  std::uniform_real_distribution<double> x(0.0, 1.0), y(0.0, 2.0);
  for (int sample = 0; sample < 100; ++sample) {
    const Vector3d p(x(rng), y(rng), x(rng));
    const TreeLocation deepest = *locator.locate(tree, p, 0.0);
    for (int level = 0; level <= tree.level(deepest.node); ++level) {
      const TreeLocation at = *locator.locate(tree, p, 0.0, level);
      EXPECT_EQ(tree.level(at.node), level);
      EXPECT_GE(at.barycentric.minCoeff(), -1e-12);
      // On the path to the deepest node, unless p sits on a face between two candidates.
      NodeId ancestor = deepest.node;
      while (tree.level(ancestor) > level)
        ancestor = tree.parent(ancestor);
      if (at.node != ancestor) {
        EXPECT_GE(barycentric(p, tree.tet_positions(ancestor)).minCoeff(), -1e-12);
      }
    }
  }
}

TEST(TreePointLocation, RefinesLazilyOnTheWayDown) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 2, 2}), 6);
  const TreePointLocator locator(tree);
  const Vector3d p(0.3141, 0.2718, 0.5772);
  const std::optional<TreeLocation> found = locator.locate_and_refine(tree, p, 0.0, 6);
  ASSERT_TRUE(found);
  EXPECT_EQ(tree.level(found->node), 6);
  EXPECT_EQ(tree.num_nodes(), tree.num_roots() + 6 * 8);  // one path, eight children per level
  EXPECT_LT((tree.tet_positions(found->node) * found->barycentric - p).norm(), 1e-14);
  EXPECT_GE(found->barycentric.minCoeff(), -1e-12);
  // Same query again creates nothing and lands in the same node.
  const std::optional<TreeLocation> again = locator.locate_and_refine(tree, p, 0.0, 6);
  EXPECT_EQ(again->node, found->node);
  EXPECT_EQ(tree.num_nodes(), tree.num_roots() + 6 * 8);
  // Outside the mesh beyond the tolerance: nothing.
  EXPECT_FALSE(locator.locate(tree, Vector3d(1.5, 0.5, 0.5), 0.1));
  const std::optional<TreeLocation> near = locator.locate(tree, Vector3d(1.05, 0.5, 0.5), 0.1);
  ASSERT_TRUE(near);
  EXPECT_LT(near->barycentric.minCoeff(), 0.0);
  EXPECT_LT((tree.tet_positions(near->node) * near->barycentric - Vector3d(1.05, 0.5, 0.5)).norm(),
            1e-14);
}

TEST(TreePointLocation, RootCoordinatesFollowTetVertexOrder) {
  std::mt19937 rng(9);
  const TetTree tree = random_tree(rng);
  const TreePointLocator locator(tree);
  const Vector3d p = tree.tet_positions(4).rowwise().mean();  // centroid of the flipped root
  const std::optional<TreeLocation> root = locator.locate_root(p, 0.0);
  ASSERT_TRUE(root);
  EXPECT_EQ(root->node, 4);
  EXPECT_LT((tree.tet_positions(4) * root->barycentric - p).norm(), 1e-14);
}

}  // namespace
}  // namespace strata
