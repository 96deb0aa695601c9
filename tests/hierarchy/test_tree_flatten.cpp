// Flattening the tree into a TetMesh: conformity of uniform refinement, maps back to the tree,
// adaptive cuts, and that core's ElasticModel accepts the result.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "hierarchy/hierarchy_test_utils.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/hierarchy/tree_flatten.hpp"
#include "strata/hierarchy/uniform_refinement.hpp"

namespace strata {
namespace {

TEST(TreeFlatten, UniformRefinementIsConforming) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.5), {3, 2, 2});
  const Index coarse_faces = boundary_faces(coarse.tets).rows();
  for (int level = 0; level <= 2; ++level) {
    const TetMesh fine = uniform_refinement(coarse, level);
    const double scale = std::pow(8.0, level);
    ASSERT_EQ(fine.tets.rows(), coarse.tets.rows() * static_cast<Index>(scale));
    EXPECT_NO_THROW(validate_tet_mesh(fine, "refined box"));
    TetMesh copy = fine;
    EXPECT_EQ(orient_tets(copy), 0);  // all positively oriented
    // Recursive summation of #T positive terms: error ≤ #T · ε · V.
    EXPECT_NEAR(mesh_volume(fine), 3.0, 3.0 * 2.3e-16 * static_cast<double>(fine.tets.rows()));
    // Every interior face is matched by a neighbour with the same vertex ids: only the
    // refined coarse boundary remains, each coarse triangle split into 4^level.
    EXPECT_EQ(boundary_faces(fine.tets).rows(),
              coarse_faces * static_cast<Index>(std::pow(4.0, level)));
    // Coarse vertices keep their indices.
    EXPECT_EQ(fine.vertices.topRows(coarse.vertices.rows()), coarse.vertices);
    // Euler characteristic of a ball: V − E + F − T = 1.
    std::set<std::pair<int, int>> edges;
    std::set<std::array<int, 3>> faces;
    for (Index t = 0; t < fine.tets.rows(); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          edges.insert(std::minmax(fine.tets(t, a), fine.tets(t, b)));
          for (int c = b + 1; c < 4; ++c) {
            std::array<int, 3> face{fine.tets(t, a), fine.tets(t, b), fine.tets(t, c)};
            std::sort(face.begin(), face.end());
            faces.insert(face);
          }
        }
    EXPECT_EQ(fine.vertices.rows() - static_cast<Index>(edges.size()) +
                  static_cast<Index>(faces.size()) - fine.tets.rows(),
              1);
  }
}

TEST(TreeFlatten, MapsLeadBackToTheTree) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 2, 2}), 3);
  tree.refine(tree.refine(7) + 3);
  tree.refine(20);
  const FlatTreeMesh flat = flatten_leaves(tree);
  ASSERT_EQ(flat.mesh.tets.rows(), tree.num_leaves());
  ASSERT_EQ(flat.tet_nodes.size(), static_cast<std::size_t>(tree.num_leaves()));
  ASSERT_EQ(flat.tet_levels.size(), flat.tet_nodes.size());
  ASSERT_EQ(flat.tree_vertices.size(), static_cast<std::size_t>(flat.mesh.vertices.rows()));
  ASSERT_EQ(flat.mesh_vertices.size(), static_cast<std::size_t>(tree.vertex_capacity()));
  for (Index t = 0; t < flat.mesh.tets.rows(); ++t) {
    EXPECT_EQ(flat.tet_levels[t], tree.level(flat.tet_nodes[t]));
    const std::array<int, 4> v = tree.tet_vertices(flat.tet_nodes[t]);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(flat.tree_vertices[flat.mesh.tets(t, i)], v[i]);
      EXPECT_EQ(flat.mesh_vertices[v[i]], flat.mesh.tets(t, i));
    }
    const Matrix3x4d x = tree.tet_positions(flat.tet_nodes[t]);
    for (int i = 0; i < 4; ++i)
      EXPECT_EQ(flat.mesh.vertices.row(flat.mesh.tets(t, i)), x.col(i).transpose());
  }
  for (std::size_t v = 0; v < flat.tree_vertices.size(); ++v)
    EXPECT_EQ(flat.mesh_vertices[flat.tree_vertices[v]], static_cast<int>(v));
  EXPECT_NEAR(mesh_volume(flat.mesh), 1.0, 1e-14);
  TetMesh copy = flat.mesh;
  EXPECT_EQ(remove_unreferenced_vertices(copy), 0);
}

TEST(TreeFlatten, FirstUseNumberingIsTheTreeIdNumberingPermuted) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 2, 2}), 3);
  tree.refine(tree.refine(30) + 3);
  tree.refine(2);
  const std::vector<NodeId> leaves = tree.leaves();
  const FlatTreeMesh by_id = flatten_nodes(tree, leaves);
  const FlatTreeMesh by_use = flatten_nodes(tree, leaves, VertexNumbering::first_use);
  ASSERT_EQ(by_use.mesh.vertices.rows(), by_id.mesh.vertices.rows());
  ASSERT_EQ(by_use.mesh.tets.rows(), by_id.mesh.tets.rows());
  // Numbered by first use: scanning the tets in order, each new vertex is the next number.
  int next = 0;
  for (Index t = 0; t < by_use.mesh.tets.rows(); ++t)
    for (int i = 0; i < 4; ++i) {
      const int v = by_use.mesh.tets(t, i);
      EXPECT_LE(v, next);
      if (v == next) ++next;
    }
  EXPECT_EQ(next, by_use.mesh.vertices.rows());
  // The same tree vertices, positions and tets, only renumbered.
  for (Index t = 0; t < by_use.mesh.tets.rows(); ++t)
    for (int i = 0; i < 4; ++i)
      EXPECT_EQ(by_use.tree_vertices[by_use.mesh.tets(t, i)],
                by_id.tree_vertices[by_id.mesh.tets(t, i)]);
  for (Index v = 0; v < by_use.mesh.vertices.rows(); ++v) {
    const int tree_vertex = by_use.tree_vertices[v];
    EXPECT_EQ(by_use.mesh_vertices[tree_vertex], static_cast<int>(v));
    EXPECT_EQ(by_use.mesh.vertices.row(v),
              by_id.mesh.vertices.row(by_id.mesh_vertices[tree_vertex]));
  }
  // tree_id keeps increasing tree ids.
  EXPECT_TRUE(std::is_sorted(by_id.tree_vertices.begin(), by_id.tree_vertices.end()));
}

TEST(TreeFlatten, AdaptiveLeavesHaveHangingVerticesOnly) {
  // One refined root among unrefined neighbours: the mesh tiles the box (volume), but faces on
  // the refined root's boundary shared with coarse neighbours are not matched (hanging vertices,
  // to be constrained by the next part).
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  TetTree tree(coarse, 2);
  tree.refine(0);
  const FlatTreeMesh flat = flatten_leaves(tree);
  EXPECT_NEAR(mesh_volume(flat.mesh), 1.0, 1e-14);
  EXPECT_GT(boundary_faces(flat.mesh.tets).rows(), boundary_faces(coarse.tets).rows());
  // Refining every root restores conformity.
  for (NodeId r = 1; r < tree.num_roots(); ++r)
    tree.refine(r);
  EXPECT_EQ(boundary_faces(flatten_leaves(tree).mesh.tets).rows(),
            4 * boundary_faces(coarse.tets).rows());
}

TEST(TreeFlatten, ElasticModelRunsOnTheFlatMesh) {
  const TetMesh fine =
      uniform_refinement(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1}), 2);
  Material material;  // StVK
  const ElasticModel model(fine.vertices, fine.tets, material);
  EXPECT_NEAR(model.energy(flatten(fine.vertices)), 0.0, 1e-12);
  // A uniform stretch x ↦ diag(s, 1, 1) x: Green strain E = diag((s² − 1)/2, 0, 0) in every tet,
  // Ψ = V · (μ tr E² + λ/2 (tr E)²) = V (μ + λ/2) e².
  const double s = 1.01, e = (s * s - 1) / 2;
  const LameParameters lame = material.lame();
  const VectorXd stretched = flatten(fine.vertices * Vector3d(s, 1.0, 1.0).asDiagonal());
  const double expected = 1.0 * (lame.mu + lame.lambda / 2) * e * e;
  EXPECT_NEAR(model.energy(stretched), expected, 1e-10 * expected);
}

}  // namespace
}  // namespace strata
