// The constrained spaces of nested cuts are nested subspaces of one conforming P1 space, so the
// linear-elastic potential energy minimum can only decrease under refinement (Céa / Rayleigh–Ritz):
// Π*(roots) ≥ Π*(mixed cut) ≥ Π*(uniform finest level). A cantilever clamped at x = 0 under
// gravity, solved on x = C q with K_q = Pᵀ K P and f_q = Pᵀ f.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/fem/tet_rest_data.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"

namespace strata {
namespace {

// Minimum of Π(q) = ½ uᵀ K_q u − f_qᵀ u over displacements u of the free vertices, with the
// vertices on x = 0 clamped; returns Π* = −½ f_qᵀ u*.
double clamped_minimum_energy(const ActiveCut& cut) {
  const ConstrainedCut c = flatten_cut(cut);
  const HangingConstraints& hc = c.constraints;
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  const ElasticModel model(c.flat.mesh.vertices, c.flat.mesh.tets, material);
  SparseMatrixd K;
  model.stiffness(model.rest_positions(), K, false);

  // Gravity: the lumped load ρ g V_t / 4 per tet corner is the consistent P1 load.
  const VectorXd m = lumped_vertex_mass(model.rest_data().rest_volume, c.flat.mesh.tets,
                                        c.flat.mesh.vertices.rows(), material.density);
  VectorXd f = VectorXd::Zero(3 * m.size());
  for (Index v = 0; v < m.size(); ++v)
    f[3 * v + 2] = -9.81 * m[v];
  const SparseMatrixd Kq = hc.reduce_matrix(K);
  const VectorXd fq = hc.reduce(f);

  std::vector<int> dofs;
  for (Index i = 0; i < hc.num_free(); ++i)
    if (c.flat.mesh.vertices(hc.free_vertices()[i], 0) > 0.0)
      for (int k = 0; k < 3; ++k)
        dofs.push_back(static_cast<int>(3 * i + k));
  std::vector<int> reduced_index(static_cast<std::size_t>(Kq.rows()), -1);
  for (std::size_t j = 0; j < dofs.size(); ++j)
    reduced_index[dofs[j]] = static_cast<int>(j);
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index col = 0; col < Kq.outerSize(); ++col)
    for (SparseMatrixd::InnerIterator it(Kq, col); it; ++it)
      if (reduced_index[it.row()] >= 0 && reduced_index[col] >= 0)
        triplets.emplace_back(reduced_index[it.row()], reduced_index[col], it.value());
  const auto n = static_cast<Index>(dofs.size());
  SparseMatrixd A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  VectorXd b(n);
  for (Index j = 0; j < n; ++j)
    b[j] = fq[dofs[j]];
  const Eigen::SimplicialLDLT<SparseMatrixd> solver(A);
  EXPECT_EQ(solver.info(), Eigen::Success);
  EXPECT_GT(solver.vectorD().minCoeff(), 0.0);  // the clamped constrained system is SPD
  const VectorXd u = solver.solve(b);
  EXPECT_LE((A * u - b).norm(), 1e-9 * b.norm());
  return -0.5 * b.dot(u);
}

TEST(HangingNestedSpaces, EnergyDecreasesUnderRefinement) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 0.5, 0.5), {2, 2, 2}), 2);
  const double roots = clamped_minimum_energy(ActiveCut(tree));

  // The half next to the clamp (largest strain) at level 2 beside level-0 tets, then balanced.
  ActiveCut mixed(tree);
  std::vector<NodeId> near_clamp;
  for (const NodeId n : mixed.sorted_nodes())
    if (tree.tet_positions(n).row(0).minCoeff() == 0.0) near_clamp.push_back(n);
  ASSERT_FALSE(near_clamp.empty());
  for (const NodeId n : near_clamp) {
    const NodeId first = mixed.refine(n);
    for (int k = 0; k < 8; ++k)
      mixed.refine(first + k);
  }
  const double unbalanced = clamped_minimum_energy(mixed);
  const Index balancing = balance_cut(mixed);
  EXPECT_GT(balancing, 0);
  const double balanced = clamped_minimum_energy(mixed);
  const double level1 = clamped_minimum_energy(ActiveCut::uniform(tree, 1));
  const double level2 = clamped_minimum_energy(ActiveCut::uniform(tree, 2));

  // Strictly decreasing along nested spaces (round-off ≈ 1e-12 relative).
  const double tol = 1e-10 * std::abs(level2);
  EXPECT_LT(unbalanced, roots - tol);
  EXPECT_LT(balanced, unbalanced - tol);  // balancing enlarges the space
  EXPECT_LT(level2, balanced - tol);
  EXPECT_LT(level2, level1 - tol);
  EXPECT_LT(level1, roots - tol);
  RecordProperty("energies", std::to_string(roots) + " " + std::to_string(unbalanced) + " " +
                                 std::to_string(balanced) + " " + std::to_string(level1) + " " +
                                 std::to_string(level2) + " balancing " +
                                 std::to_string(balancing));
}

}  // namespace
}  // namespace strata
