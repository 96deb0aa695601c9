#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// A 0.2 × 0.2 × 1 column clamped at its base under gravity with a sideways component: at static
/// equilibrium the base reaction balances the total weight and its moment balances the weight's
/// moment about the base centroid, evaluated at the deformed positions.
TEST(SimPhysics, GravityLoadedColumnReactionBalancesTheWeight) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.2, 0.2, 1.0), {2, 2, 8});
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  DirichletSpec base;
  base.name = "fixed[0]";
  base.region = BoxRegion{Vector3d(-1, -1, 0), Vector3d(1, 1, 0)};
  const Vector3d gravity(3.0, -1.0, -9.81);
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 2;
  Simulation sim(mesh, {.material = material, .dirichlet = {base}, .gravity = gravity}, settings);
  while (!sim.finished())
    sim.advance();

  const VectorXd& m = sim.vertex_mass();
  const double total_mass = m.sum();
  EXPECT_NEAR(total_mass, 1000.0 * 0.04, 1e-10);
  const Vector3d weight = total_mass * gravity;
  const auto reactions = sim.reactions();
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_LT((reactions[0].force + weight).norm(), 1e-8 * weight.norm());

  // Independent moment: −Σ (x_i − c) × m_i g over every vertex, deformed positions.
  const Vector3d c = reactions[0].moment_center;
  EXPECT_LT((c - Vector3d(0.1, 0.1, 0.0)).norm(), 1e-12);
  Vector3d expected_moment = Vector3d::Zero();
  const VectorXd& x = sim.positions();
  for (Index v = 0; v < m.size(); ++v)
    expected_moment -= (x.segment<3>(3 * v) - c).cross(m[v] * gravity);
  EXPECT_LT((reactions[0].moment - expected_moment).norm(), 1e-8 * weight.norm() * 1.0);
  // The column really deflected (the moment uses deformed lever arms).
  EXPECT_GT((x - sim.model().rest_positions()).lpNorm<Eigen::Infinity>(), 1e-4);
}

}  // namespace
}  // namespace strata
