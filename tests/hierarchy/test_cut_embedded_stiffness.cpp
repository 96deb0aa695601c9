// The reduced stiffness K_q = Pᵀ K P of an active cut (EmbeddedElasticModel): tets of free
// vertices assemble straight into K_q, the tets touching a hanging vertex through a mesh-level
// layer. Both kinds against the sparse triple product of the whole mesh's K (HangingConstraints::
// reduce_matrix, an independent path), for every material model, exact and PSD-projected; an
// embedding that only renumbers the vertices (no layer); and the values bit for bit the same at
// one and two threads.
#include <gtest/gtest.h>

#include <random>

#include "strata/core/common/parallel.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/material_registry.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"

namespace strata {
namespace {

/// A 2 × 1 × 1 box of 4 × 2 × 2 cells with 3 levels: the tets that start below x = 0.6 refined
/// once, and of their children those next to x = 0 or reaching x = 1 refined again. Level-2 tets
/// then face level-0 tets at x = 1 (chains of hanging vertices), and the cut has tets of free
/// vertices only and tets with hanging vertices.
ConstrainedCut graded_box(TetTree& tree) {
  ActiveCut cut = ActiveCut::uniform(tree, 0);
  for (const NodeId n : cut.sorted_nodes())
    if (tree.tet_positions(n).row(0).minCoeff() < 0.6) cut.refine(n);
  for (const NodeId n : cut.sorted_nodes()) {
    const Eigen::RowVector4d x =
        tree.tet_positions(n).row(0);  // a copy: the positions are a temporary
    if (tree.level(n) == 1 && (x.minCoeff() < 0.2 || x.maxCoeff() > 0.99)) cut.refine(n);
  }
  return flatten_cut(cut);
}

Material material(MaterialModel model) {
  Material m;
  m.model = model;
  m.youngs_modulus = 1e6;
  m.poisson_ratio = 0.4;
  m.density = 1000.0;
  return m;
}

/// The DOF positions: rest plus a smooth bend and a random perturbation (some elements far enough
/// from rest that the PSD projection changes their Hessian).
VectorXd deformed(const VectorXd& rest, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-0.03, 0.03);
  VectorXd q = rest;
  for (Index i = 0; i < q.size() / 3; ++i) {
    const double x = rest[3 * i];
    q[3 * i + 2] += 0.3 * x * x;
    q[3 * i] *= 0.8;
    for (int c = 0; c < 3; ++c)
      q[3 * i + c] += noise(rng);
  }
  return q;
}

/// K_q equals `expected` to round-off, in the structure of `pattern`, which holds every non-zero
/// of `expected`.
void expect_reduced_stiffness(const SparseMatrixd& K_q, const SparseMatrixd& expected_sparse,
                              const SparseMatrixd& pattern) {
  const Eigen::MatrixXd expected = Eigen::MatrixXd(expected_sparse);
  const Eigen::MatrixXd actual = Eigen::MatrixXd(K_q);
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  const double scale = expected.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), 1e-12 * scale);
  ASSERT_EQ(K_q.nonZeros(), pattern.nonZeros());
  EXPECT_TRUE(std::equal(pattern.outerIndexPtr(), pattern.outerIndexPtr() + pattern.outerSize() + 1,
                         K_q.outerIndexPtr()));
  EXPECT_TRUE(std::equal(pattern.innerIndexPtr(), pattern.innerIndexPtr() + pattern.nonZeros(),
                         K_q.innerIndexPtr()));
  SparseMatrixd structure = pattern;
  std::fill(structure.valuePtr(), structure.valuePtr() + structure.nonZeros(), 1.0);
  const Eigen::MatrixXd in_pattern = Eigen::MatrixXd(structure);
  EXPECT_EQ(((expected.array() != 0.0) && (in_pattern.array() == 0.0)).count(), 0);
}

TEST(EmbeddedStiffnessOnCuts, DirectAndLayerTetsAssembleThePtKP) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.0), {4, 2, 2}), 2);
  const ConstrainedCut cut = graded_box(tree);
  ASSERT_GT(cut.constraints.num_hanging(), 0);
  ASSERT_GT(cut.constraints.max_chain_depth(), 1);
  for (const MaterialModelTraits& info : material_registry()) {
    SCOPED_TRACE(info.name);
    const ElasticModel model(cut.flat.mesh.vertices, cut.flat.mesh.tets, material(info.model));
    const EmbeddedElasticModel embedded(model, cut.constraints.matrix(),
                                        cut.constraints.free_vertices());
    ASSERT_FALSE(embedded.is_identity());
    // Both kinds of tet are present in numbers.
    EXPECT_GT(embedded.num_layer_tets(), model.num_tets() / 10);
    EXPECT_LT(embedded.num_layer_tets(), model.num_tets() * 9 / 10);
    const VectorXd q = deformed(embedded.rest_positions(), 3);
    const VectorXd x = embedded.expand(q);
    SparseMatrixd K_q;  // reused: the second assembly overwrites the first
    for (const bool project_psd : {false, true}) {
      SCOPED_TRACE(project_psd ? "projected" : "exact");
      SparseMatrixd K_mesh;
      model.stiffness(x, K_mesh, project_psd);
      embedded.stiffness(q, K_q, project_psd);
      expect_reduced_stiffness(K_q, cut.constraints.reduce_matrix(K_mesh),
                               embedded.stiffness_pattern());
    }
  }
}

TEST(EmbeddedStiffnessOnCuts, ARenumberingWithoutHangingVerticesAssemblesThePtKP) {
  // C a permutation: not the identity path, and every tet direct (no layer).
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.0), {4, 2, 2});
  const Index n = mesh.vertices.rows();
  // q ↦ (7q + 3) mod n is a permutation while the prime 7 does not divide n.
  ASSERT_NE(n % 7, 0);
  std::vector<int> dof_vertices(n);
  for (Index q = 0; q < n; ++q)
    dof_vertices[q] = static_cast<int>((7 * q + 3) % n);
  std::vector<Eigen::Triplet<double>> entries;
  for (Index q = 0; q < n; ++q)
    entries.emplace_back(dof_vertices[q], q, 1.0);
  SparseMatrixd C(n, n);
  C.setFromTriplets(entries.begin(), entries.end());
  const ElasticModel model(mesh.vertices, mesh.tets, material(MaterialModel::stvk));
  const EmbeddedElasticModel embedded(model, C, dof_vertices);
  ASSERT_FALSE(embedded.is_identity());
  EXPECT_EQ(embedded.num_layer_tets(), 0);
  const VectorXd q = deformed(embedded.rest_positions(), 9);
  SparseMatrixd P(3 * n, 3 * n);
  std::vector<Eigen::Triplet<double>> dof_entries;
  for (Index k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c)
      dof_entries.emplace_back(3 * dof_vertices[k] + c, 3 * k + c, 1.0);
  P.setFromTriplets(dof_entries.begin(), dof_entries.end());
  for (const bool project_psd : {false, true}) {
    SparseMatrixd K_mesh, K_q;
    model.stiffness(embedded.expand(q), K_mesh, project_psd);
    embedded.stiffness(q, K_q, project_psd);
    expect_reduced_stiffness(K_q, SparseMatrixd(P.transpose() * K_mesh * P),
                             embedded.stiffness_pattern());
  }
}

TEST(EmbeddedStiffnessOnCuts, ValuesAreBitwiseTheSameAtOneAndTwoThreads) {
  // 8 × 4 × 4 cells: enough chunks per colour for the two threads to share the work.
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.0), {8, 4, 4}), 2);
  const ConstrainedCut cut = graded_box(tree);
  const ElasticModel model(cut.flat.mesh.vertices, cut.flat.mesh.tets,
                           material(MaterialModel::neohookean));
  const VectorXd q = deformed(cut.constraints.restrict_to_free(model.rest_positions()), 5);
  for (const bool project_psd : {false, true}) {
    SCOPED_TRACE(project_psd ? "projected" : "exact");
    SparseMatrixd K1, K2;
    {
      ThreadLimit limit(1);
      const EmbeddedElasticModel embedded(model, cut.constraints.matrix(),
                                          cut.constraints.free_vertices());
      embedded.stiffness(q, K1, project_psd);
    }
    {
      ThreadLimit limit(2);
      const EmbeddedElasticModel embedded(model, cut.constraints.matrix(),
                                          cut.constraints.free_vertices());
      embedded.stiffness(q, K2, project_psd);
    }
    ASSERT_EQ(K1.nonZeros(), K2.nonZeros());
    EXPECT_TRUE(std::equal(K1.outerIndexPtr(), K1.outerIndexPtr() + K1.outerSize() + 1,
                           K2.outerIndexPtr()));
    EXPECT_TRUE(
        std::equal(K1.innerIndexPtr(), K1.innerIndexPtr() + K1.nonZeros(), K2.innerIndexPtr()));
    EXPECT_TRUE(std::equal(K1.valuePtr(), K1.valuePtr() + K1.nonZeros(), K2.valuePtr()));
  }
}

}  // namespace
}  // namespace strata
