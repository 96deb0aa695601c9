// Active cut: construction, validation, refine/coarsen round trips, 2:1 balance (checked against
// an independent face-neighbour search by point location).
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_balance.hpp"

namespace strata {
namespace {

TetMesh test_box() {
  return box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.5, 1.0), {2, 2, 2});
}

// Barycentric coordinates of p in the tet with columns x.
Eigen::Vector4d barycentric(const Matrix3x4d& x, const Vector3d& p) {
  Matrix3d D;
  D << x.col(1) - x.col(0), x.col(2) - x.col(0), x.col(3) - x.col(0);
  const Vector3d l = D.partialPivLu().solve(p - x.col(0));
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

// Largest level difference between face neighbours, found without the tree's topology: the
// neighbour across a face is the active tet containing a point just outside the face.
int max_face_neighbour_level_jump(const ActiveCut& cut) {
  const TetTree& tree = cut.tree();
  const std::vector<NodeId> nodes = cut.sorted_nodes();
  std::vector<Matrix3x4d> x;
  for (const NodeId n : nodes)
    x.push_back(tree.tet_positions(n));
  int jump = 0;
  for (std::size_t t = 0; t < nodes.size(); ++t) {
    const Vector3d centre = x[t].rowwise().mean();
    for (int f = 0; f < 4; ++f) {
      Vector3d face_centre = Vector3d::Zero();
      for (int i = 0; i < 4; ++i)
        if (i != f) face_centre += x[t].col(i) / 3.0;
      const Vector3d outside = face_centre + 1e-6 * (face_centre - centre);
      for (std::size_t s = 0; s < nodes.size(); ++s) {
        if (s == t || barycentric(x[s], outside).minCoeff() < -1e-12) continue;
        jump = std::max(jump, std::abs(tree.level(nodes[s]) - tree.level(nodes[t])));
      }
    }
  }
  return jump;
}

TEST(ActiveCut, RootsAndUniformLevels) {
  TetTree tree(test_box(), 2);
  const ActiveCut roots(tree);
  EXPECT_EQ(roots.size(), 48);
  EXPECT_NO_THROW(roots.validate());
  EXPECT_EQ(roots.finest_level(), 0);
  const ActiveCut level1 = ActiveCut::uniform(tree, 1);
  EXPECT_EQ(level1.size(), 48 * 8);
  EXPECT_EQ(level1.coarsest_level(), 1);
  EXPECT_EQ(level1.finest_level(), 1);
  EXPECT_NO_THROW(level1.validate());
  const ActiveCut level2 = ActiveCut::uniform(tree, 2);
  EXPECT_EQ(level2.level_counts(), (std::vector<Index>{0, 0, 48 * 64}));
  EXPECT_TRUE(is_balanced(level2));
  EXPECT_THROW(ActiveCut::uniform(tree, 3), InputError);
  // The roots cut is still valid although the tree below it has grown.
  EXPECT_NO_THROW(roots.validate());
}

TEST(ActiveCut, DepthFirstNodesFollowTheTreeWhateverTheEditOrder) {
  TetTree tree(test_box(), 3);
  const ActiveCut uniform = ActiveCut::uniform(tree, 2);
  EXPECT_EQ(uniform.depth_first_nodes(), uniform.nodes());  // the order uniform builds

  // An edited cut: the swap-removal of refined nodes scrambles nodes(); depth_first_nodes lists
  // the same nodes so that every root's and every parent's descendants are contiguous, in root
  // and child order.
  ActiveCut cut(tree);
  cut.refine(cut.refine(40) + 6);
  cut.refine(5);
  cut.refine(cut.refine(17) + 1);
  const std::vector<NodeId> order = cut.depth_first_nodes();
  std::vector<NodeId> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, cut.sorted_nodes());
  const auto root_of = [&](NodeId n) {
    while (tree.parent(n) != kNoNode)
      n = tree.parent(n);
    return n;
  };
  // Ancestor path of each node as (root, child slots…): depth-first order is lexicographic.
  const auto path = [&](NodeId n) {
    std::vector<int> slots;
    for (; tree.parent(n) != kNoNode; n = tree.parent(n))
      slots.push_back(tree.node(n).child_slot);
    slots.push_back(static_cast<int>(n));
    std::reverse(slots.begin(), slots.end());
    return slots;
  };
  for (std::size_t i = 1; i < order.size(); ++i) {
    EXPECT_LE(root_of(order[i - 1]), root_of(order[i]));
    EXPECT_LT(path(order[i - 1]), path(order[i])) << "at " << i;
  }
  EXPECT_NE(order, cut.nodes());  // the edits did scramble nodes()
}

TEST(ActiveCut, ListConstructorValidates) {
  TetTree tree(test_box(), 2);
  const NodeId first = tree.refine(3);
  std::vector<NodeId> nodes;
  for (NodeId r = 0; r < 48; ++r)
    if (r != 3) nodes.push_back(r);
  for (int k = 0; k < 8; ++k)
    nodes.push_back(first + k);
  EXPECT_NO_THROW(ActiveCut(tree, nodes));

  std::vector<NodeId> gap = nodes;
  gap.pop_back();  // one child missing
  EXPECT_THROW(ActiveCut(tree, gap), InputError);
  std::vector<NodeId> nested = nodes;
  nested.push_back(3);  // parent and its children
  EXPECT_THROW(ActiveCut(tree, nested), InputError);
  std::vector<NodeId> twice = nodes;
  twice.push_back(0);
  EXPECT_THROW(ActiveCut(tree, twice), InputError);
  std::vector<NodeId> dead = nodes;
  dead.push_back(static_cast<NodeId>(tree.pool_size()));
  EXPECT_THROW(ActiveCut(tree, dead), InputError);
}

TEST(ActiveCut, RefineThenCoarsenRestoresTheCut) {
  TetTree tree(test_box(), 3);
  ActiveCut cut(tree);
  cut.refine(cut.refine(7) + 2);
  const std::vector<NodeId> original = cut.sorted_nodes();

  const NodeId a = cut.refine(11);
  const NodeId b = cut.refine(a + 5);
  const NodeId c = cut.refine(b + 7);
  EXPECT_EQ(cut.size(), static_cast<Index>(original.size()) + 3 * 7);
  EXPECT_NO_THROW(cut.validate());
  EXPECT_FALSE(cut.can_coarsen(11));  // a child is refined
  EXPECT_THROW(cut.coarsen(11), std::logic_error);
  EXPECT_THROW(cut.refine(11), std::logic_error);  // not active
  EXPECT_THROW(cut.refine(c), std::logic_error);   // at the maximum level
  cut.coarsen(tree.parent(c));
  cut.coarsen(tree.parent(b));
  cut.coarsen(11);
  EXPECT_EQ(cut.sorted_nodes(), original);
  EXPECT_NO_THROW(cut.validate());

  // Releasing the nodes gives the tree back its original size.
  const Index nodes_before = tree.num_nodes();
  cut.refine(cut.refine(30) + 1);
  EXPECT_EQ(tree.num_nodes(), nodes_before + 16);
  cut.coarsen(tree.child(30, 1), true);
  cut.coarsen(30, true);
  EXPECT_EQ(tree.num_nodes(), nodes_before);
  EXPECT_EQ(cut.sorted_nodes(), original);
}

TEST(ActiveCut, BalanceRefinesCoarseNeighbours) {
  TetTree tree(test_box(), 3);
  ActiveCut cut(tree);
  const NodeId first = cut.refine(0);
  cut.refine(first + 1);
  cut.refine(first + 6);
  EXPECT_EQ(max_face_neighbour_level_jump(cut), 2);
  const std::vector<BalanceViolation> violations = balance_violations(cut);
  ASSERT_FALSE(violations.empty());
  for (const BalanceViolation& v : violations) {
    EXPECT_EQ(v.host_level, 0);
    EXPECT_EQ(v.fine_level, 2);
    EXPECT_TRUE(cut.is_active(v.host));
    EXPECT_TRUE(cut.is_active(v.fine_node));
  }
  const Index refined = balance_cut(cut);
  EXPECT_GT(refined, 0);
  EXPECT_TRUE(is_balanced(cut));
  EXPECT_NO_THROW(cut.validate());
  EXPECT_EQ(max_face_neighbour_level_jump(cut), 1);
  // Only the coarse side was refined: nothing beyond level 2.
  EXPECT_EQ(cut.finest_level(), 2);

  // Refining a level-2 node with balance keeps the cut balanced and reaches level 3.
  const NodeId deep = refine_balanced(cut, tree.child(first + 1, 3));
  EXPECT_EQ(tree.level(deep), 3);
  EXPECT_TRUE(is_balanced(cut));
  EXPECT_EQ(max_face_neighbour_level_jump(cut), 1);
  EXPECT_NO_THROW(cut.validate());
}

}  // namespace
}  // namespace strata
