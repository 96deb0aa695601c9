// The node pool: lazy refinement, shared midpoints, coarsening and free-list reuse, vertex
// lifecycle, memory proportional to what exists.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "hierarchy/hierarchy_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/hierarchy/tet_tree.hpp"
#include "strata/hierarchy/tree_point_location.hpp"
#include "strata/hierarchy/tree_size.hpp"

namespace strata {
namespace {

TetMesh unit_box(int cells) {
  return box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {cells, cells, cells});
}

// Two coarse tets sharing a face, and the three shared vertices.
struct FacePair {
  NodeId a = kNoNode, b = kNoNode;
  std::set<int> face;
};

FacePair find_face_neighbours(const TetMesh& mesh) {
  for (Index s = 0; s < mesh.tets.rows(); ++s)
    for (Index t = s + 1; t < mesh.tets.rows(); ++t) {
      std::set<int> common;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          if (mesh.tets(s, i) == mesh.tets(t, j)) common.insert(mesh.tets(s, i));
      if (common.size() == 3) return {static_cast<NodeId>(s), static_cast<NodeId>(t), common};
    }
  return {};
}

// Faces (sorted vertex triples) of the children of `n` whose vertices all lie in `allowed`.
std::set<std::array<int, 3>> child_faces_within(const TetTree& tree, NodeId n,
                                                const std::set<int>& allowed) {
  std::set<std::array<int, 3>> faces;
  for (int k = 0; k < 8; ++k) {
    const std::array<int, 4>& v = tree.bey_vertices(tree.child(n, k));
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> face{};
      int f = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) face[f++] = v[i];
      std::sort(face.begin(), face.end());
      if (std::all_of(face.begin(), face.end(), [&](int x) { return allowed.count(x) > 0; }))
        faces.insert(face);
    }
  }
  return faces;
}

std::set<int> live_vertices(const TetTree& tree) {
  std::set<int> live;
  for (int v = 0; v < tree.vertex_capacity(); ++v)
    if (tree.is_vertex_alive(v)) live.insert(v);
  return live;
}

TEST(TetTree, RootsAreTheCoarseTets) {
  const TetMesh mesh = unit_box(2);
  const TetTree tree(mesh, 3);
  EXPECT_EQ(tree.num_roots(), mesh.tets.rows());
  EXPECT_EQ(tree.num_nodes(), mesh.tets.rows());
  EXPECT_EQ(tree.num_leaves(), mesh.tets.rows());
  EXPECT_EQ(tree.num_vertices(), mesh.vertices.rows());
  EXPECT_EQ(tree.num_coarse_vertices(), mesh.vertices.rows());
  for (NodeId r = 0; r < tree.num_roots(); ++r) {
    EXPECT_EQ(tree.level(r), 0);
    EXPECT_EQ(tree.parent(r), kNoNode);
    EXPECT_EQ(tree.node(r).root, r);
    EXPECT_TRUE(tree.is_leaf(r));
    for (int i = 0; i < 4; ++i)
      EXPECT_EQ(tree.bey_vertices(r)[i], mesh.tets(r, i));
  }
}

TEST(TetTree, RefineCreatesEightChildrenOnce) {
  TetTree tree(unit_box(1), 2);
  const NodeId first = tree.refine(3);
  EXPECT_EQ(tree.num_nodes(), 6 + 8);
  EXPECT_EQ(tree.num_leaves(), 6 + 7);
  EXPECT_EQ(tree.num_midpoints(), 6);
  EXPECT_EQ(tree.refine(3), first);  // idempotent
  EXPECT_EQ(tree.num_nodes(), 6 + 8);
  EXPECT_EQ(tree.num_midpoints(), 6);
  for (int k = 0; k < 8; ++k) {
    const NodeId c = tree.child(3, k);
    EXPECT_EQ(c, first + k);
    EXPECT_EQ(tree.parent(c), 3);
    EXPECT_EQ(tree.level(c), 1);
    EXPECT_EQ(tree.node(c).child_slot, k);
    EXPECT_EQ(tree.node(c).root, 3);
  }
  // Every new vertex is the exact midpoint of the parents it records.
  for (int v = static_cast<int>(tree.num_coarse_vertices()); v < tree.vertex_capacity(); ++v) {
    const std::array<int, 2>& p = tree.vertex_parents(v);
    const Vector3d expected = 0.5 * (tree.vertex_position(p[0]) + tree.vertex_position(p[1]));
    EXPECT_EQ(tree.vertex_position(v), expected);
    EXPECT_EQ(tree.midpoint(p[0], p[1]), v);
    EXPECT_EQ(tree.midpoint(p[1], p[0]), v);
    EXPECT_EQ(tree.vertex_level(v), 1);
  }
  // Level 2 is the maximum here.
  const NodeId grandchild = tree.refine(first + 5);
  EXPECT_EQ(tree.level(grandchild), 2);
  EXPECT_FALSE(tree.can_refine(grandchild));
  EXPECT_THROW(tree.refine(grandchild), std::logic_error);
}

TEST(TetTree, FaceNeighboursShareTheirMidpoints) {
  const TetMesh mesh = unit_box(1);
  const FacePair pair = find_face_neighbours(mesh);
  ASSERT_NE(pair.a, kNoNode);
  TetTree tree(mesh, 2);
  tree.refine(pair.a);
  tree.refine(pair.b);
  // Two tets have 6 + 6 edges, 3 of them shared.
  EXPECT_EQ(tree.num_midpoints(), 9);

  std::set<int> face_points(pair.face);
  const std::vector<int> f(pair.face.begin(), pair.face.end());
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const int m = tree.midpoint(f[i], f[j]);
      ASSERT_GE(m, 0);
      face_points.insert(m);
    }
  const std::set<std::array<int, 3>> faces_a = child_faces_within(tree, pair.a, face_points);
  const std::set<std::array<int, 3>> faces_b = child_faces_within(tree, pair.b, face_points);
  EXPECT_EQ(faces_a.size(), 4u);  // the shared face is split into four triangles
  EXPECT_EQ(faces_a, faces_b);    // with identical vertex indices from both sides
}

TEST(TetTree, CoarsenKeepsMidpointsANeighbourStillUses) {
  const TetMesh mesh = unit_box(1);
  const FacePair pair = find_face_neighbours(mesh);
  TetTree tree(mesh, 2);
  tree.refine(pair.a);
  tree.refine(pair.b);
  const std::vector<int> f(pair.face.begin(), pair.face.end());
  const int shared = tree.midpoint(f[0], f[1]);

  EXPECT_TRUE(tree.coarsen(pair.a));
  EXPECT_EQ(tree.num_midpoints(), 6);  // b's six edges
  EXPECT_TRUE(tree.is_vertex_alive(shared));
  EXPECT_EQ(tree.midpoint(f[0], f[1]), shared);
  EXPECT_EQ(tree.num_vertices(), mesh.vertices.rows() + 6);

  EXPECT_TRUE(tree.coarsen(pair.b));
  EXPECT_EQ(tree.num_midpoints(), 0);
  EXPECT_FALSE(tree.is_vertex_alive(shared));
  EXPECT_EQ(tree.midpoint(f[0], f[1]), -1);
  EXPECT_EQ(tree.num_vertices(), mesh.vertices.rows());
  EXPECT_FALSE(tree.coarsen(pair.b));  // already a leaf
}

TEST(TetTree, RefineThenCoarsenIsTheIdentity) {
  TetTree tree(unit_box(2), 4);
  // Some structure first, so the state is not trivial.
  tree.refine(tree.refine(tree.refine(5) + 2) + 7);
  tree.refine(11);
  const Index nodes = tree.num_nodes(), leaves = tree.num_leaves();
  const Index vertices = tree.num_vertices(), midpoints = tree.num_midpoints();
  const std::vector<NodeId> leaf_list = tree.leaves();
  const std::set<int> live = live_vertices(tree);
  const Index pool = tree.pool_size();

  // A leaf refined twice deep, then released bottom-up.
  const NodeId target = tree.child(11, 4);
  const NodeId first = tree.refine(target);
  const NodeId second = tree.refine(first + 1);
  const Index pool_after_refine = tree.pool_size();
  const std::set<int> live_after_refine = live_vertices(tree);
  const Index capacity_after_refine = tree.vertex_capacity();
  EXPECT_EQ(tree.num_nodes(), nodes + 16);
  EXPECT_FALSE(tree.can_coarsen(target));
  EXPECT_THROW(tree.coarsen(target), std::logic_error);  // a child has children
  EXPECT_TRUE(tree.coarsen(first + 1));
  EXPECT_TRUE(tree.coarsen(target));

  EXPECT_EQ(tree.num_nodes(), nodes);
  EXPECT_EQ(tree.num_leaves(), leaves);
  EXPECT_EQ(tree.num_vertices(), vertices);
  EXPECT_EQ(tree.num_midpoints(), midpoints);
  EXPECT_EQ(tree.leaves(), leaf_list);
  EXPECT_EQ(live_vertices(tree), live);
  EXPECT_EQ(tree.pool_size(), pool + 16);  // the slots stay, on the free list
  EXPECT_EQ(tree.num_free_blocks(), 2);
  EXPECT_FALSE(tree.is_alive(first));
  EXPECT_FALSE(tree.is_alive(second));

  // Refining again reuses the released blocks and vertex ids: nothing new is allocated.
  const NodeId again = tree.refine(target);
  tree.refine(again + 1);
  EXPECT_EQ(tree.pool_size(), pool_after_refine);
  EXPECT_EQ(tree.num_free_blocks(), 0);
  EXPECT_EQ(tree.vertex_capacity(), capacity_after_refine);
  EXPECT_EQ(live_vertices(tree), live_after_refine);
  EXPECT_TRUE(again == first || again == second);

  // coarsen_subtree releases everything below a root in one call.
  EXPECT_EQ(tree.coarsen_subtree(11), 8 + 16);
  EXPECT_EQ(tree.coarsen_subtree(5), 24);
  EXPECT_EQ(tree.num_nodes(), tree.num_roots());
  EXPECT_EQ(tree.num_vertices(), tree.num_coarse_vertices());
  EXPECT_EQ(tree.num_midpoints(), 0);
}

TEST(TetTree, UseCountsMatchTheLiveNodes) {
  TetTree tree(unit_box(2), 3);
  std::mt19937 rng(11);
  for (int step = 0; step < 300; ++step) {
    std::uniform_int_distribution<NodeId> pick(0, static_cast<NodeId>(tree.pool_size() - 1));
    const NodeId n = pick(rng);
    if (!tree.is_alive(n)) continue;
    if (tree.can_coarsen(n) && step % 3 == 0)
      tree.coarsen(n);
    else if (tree.can_refine(n))
      tree.refine(n);
  }
  std::vector<int> expected(tree.vertex_capacity(), 0);
  Index alive = 0, leaves = 0;
  for (NodeId n = 0; n < tree.pool_size(); ++n) {
    if (!tree.is_alive(n)) continue;
    ++alive;
    leaves += tree.is_leaf(n) ? 1 : 0;
    for (const int v : tree.bey_vertices(n)) {
      ASSERT_TRUE(tree.is_vertex_alive(v));
      ++expected[v];
    }
  }
  EXPECT_EQ(alive, tree.num_nodes());
  EXPECT_EQ(leaves, tree.num_leaves());
  Index live = 0, midpoints = 0;
  for (int v = 0; v < tree.vertex_capacity(); ++v) {
    EXPECT_EQ(tree.vertex_use_count(v), expected[v]) << "vertex " << v;
    if (!tree.is_vertex_alive(v)) continue;
    ++live;
    if (tree.vertex_parents(v)[0] >= 0) {
      ++midpoints;
      EXPECT_GT(expected[v], 0);  // a midpoint lives exactly as long as some node uses it
    }
  }
  EXPECT_EQ(live, tree.num_vertices());
  EXPECT_EQ(midpoints, tree.num_midpoints());
}

TEST(TetTree, MemoryFollowsTheCreatedNodes) {
  // 12³ cells · 6 = 10 368 coarse tets; five levels would allow 340 million leaves.
  const TetMesh mesh = unit_box(12);
  const int max_level = 5;
  TetTree tree(mesh, max_level);
  EXPECT_EQ(potential_leaf_count(mesh.tets.rows(), max_level), 339738624u);
  const std::size_t bytes_before = tree.memory_bytes();
  EXPECT_EQ(tree.pool_size(), mesh.tets.rows());

  // Refine down to level 5 around 40 points near one corner.
  const TreePointLocator locator(tree);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> corner(0.0, 0.08);
  for (int i = 0; i < 40; ++i) {
    const Vector3d p(corner(rng), corner(rng), corner(rng));
    const std::optional<TreeLocation> found = locator.locate_and_refine(tree, p, 0.0, max_level);
    ASSERT_TRUE(found);
    EXPECT_EQ(tree.level(found->node), max_level);
  }
  const Index created = tree.num_nodes() - tree.num_roots();
  EXPECT_GT(created, 8 * 100);  // a few hundred refinements
  EXPECT_LT(created, 8 * 200);
  EXPECT_EQ(tree.pool_size(), tree.num_nodes());  // the pool holds exactly the created nodes
  const Index midpoints = tree.num_midpoints();
  EXPECT_LE(midpoints, 6 * created / 8);
  EXPECT_EQ(tree.vertex_capacity(), mesh.vertices.rows() + midpoints);

  // Bytes added: nodes (32 B, slack ≤ max(created, 1024)), midpoint vertices (37 B, same slack),
  // hash table (≤ 4 slots of 16 B per midpoint, or its minimum of 16 slots).
  const std::size_t added = tree.memory_bytes() - bytes_before;
  const std::size_t bound = 32 * (created + std::max<Index>(created, 1024)) +
                            37 * (midpoints + std::max<Index>(midpoints, 1024)) +
                            16 * std::max<Index>(4 * midpoints, 16);
  EXPECT_LE(added, bound);
  EXPECT_LT(tree.memory_bytes(), 200 * static_cast<std::size_t>(tree.num_nodes()));
}

TEST(TetTree, RejectsBadInput) {
  EXPECT_THROW(TetTree(unit_box(1), -1), InputError);
  EXPECT_THROW(TetTree(unit_box(1), TetTree::kMaxSupportedLevel + 1), InputError);
  TetMesh flat = unit_box(1);
  flat.vertices.col(2).setZero();  // every tet degenerate
  EXPECT_THROW(TetTree(flat, 2), InputError);
  TetTree tree(unit_box(1), 1);
  EXPECT_THROW(tree.refine(1000), std::logic_error);
  EXPECT_THROW(tree.node(-1), std::logic_error);
}

}  // namespace
}  // namespace strata
