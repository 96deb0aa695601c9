// Carrying vertex state between cuts: affine fields survive refinement and coarsening exactly,
// shared vertices keep their values.
#include <gtest/gtest.h>

#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_transfer.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"

namespace strata {
namespace {

VectorXd affine_field(const MatrixX3d& X, const Matrix3d& A, const Vector3d& b) {
  VectorXd x(3 * X.rows());
  for (Index v = 0; v < X.rows(); ++v)
    x.segment<3>(3 * v) = A * X.row(v).transpose() + b;
  return x;
}

TEST(ActiveCutTransfer, AffineFieldsAndSharedVertices) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.5, 1.0), {2, 2, 2}), 3);
  ActiveCut cut(tree);
  cut.refine(cut.refine(5) + 2);
  Matrix3d A;
  A << 1.2, 0.1, -0.3,  //
      0.05, 0.9, 0.2,   //
      -0.1, 0.3, 1.1;
  const Vector3d b(0.5, -0.25, 1.0);

  const FlatTreeMesh before = flatten_nodes(tree, cut.nodes());
  const VectorXd x_before = affine_field(before.mesh.vertices, A, b);
  // Refine next to existing refinement and far from it.
  const NodeId first = cut.refine(tree.child(tree.child(5, 2), 7));
  cut.refine(40);
  const FlatTreeMesh refined = flatten_nodes(tree, cut.nodes());
  ASSERT_GT(refined.mesh.vertices.rows(), before.mesh.vertices.rows());
  const VectorXd x_refined = transfer_vertex_values(tree, before, x_before, refined);
  EXPECT_LE((x_refined - affine_field(refined.mesh.vertices, A, b)).cwiseAbs().maxCoeff(), 1e-14);

  // A non-affine field: shared vertices copied exactly, new ones are parent averages.
  const VectorXd wavy = VectorXd::Random(x_before.size());
  const VectorXd wavy_refined = transfer_vertex_values(tree, before, wavy, refined);
  for (std::size_t v = 0; v < refined.tree_vertices.size(); ++v) {
    const int tv = refined.tree_vertices[v];
    const int s =
        before.mesh_vertices.size() > static_cast<std::size_t>(tv) ? before.mesh_vertices[tv] : -1;
    const Vector3d got = wavy_refined.segment<3>(3 * static_cast<Index>(v));
    if (s >= 0) {
      EXPECT_EQ(got, wavy.segment<3>(3 * s));
    } else {
      const std::array<int, 2>& p = tree.vertex_parents(tv);
      const Vector3d expected = 0.5 * (wavy_refined.segment<3>(3 * refined.mesh_vertices[p[0]]) +
                                       wavy_refined.segment<3>(3 * refined.mesh_vertices[p[1]]));
      EXPECT_LE((got - expected).norm(), 1e-15);
    }
  }

  // Coarsening back: the affine field is still exact and the original mesh comes back.
  cut.coarsen(tree.parent(first));
  cut.coarsen(40);
  const FlatTreeMesh after = flatten_nodes(tree, cut.nodes());
  EXPECT_EQ(after.tree_vertices, before.tree_vertices);
  const VectorXd x_after = transfer_vertex_values(tree, refined, x_refined, after);
  EXPECT_LE((x_after - x_before).cwiseAbs().maxCoeff(), 1e-14);
  // The transferred state satisfies the new constraints for an affine field.
  const HangingConstraints constraints(tree, refined);
  EXPECT_LE((constraints.expand(constraints.restrict_to_free(x_refined)) - x_refined)
                .cwiseAbs()
                .maxCoeff(),
            1e-14);
}

TEST(ActiveCutTransfer, RejectsWrongSizes) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1}), 1);
  const FlatTreeMesh flat = flatten_leaves(tree);
  EXPECT_THROW(transfer_vertex_values(tree, flat, VectorXd::Zero(5), flat), std::logic_error);
}

}  // namespace
}  // namespace strata
