#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "fem_test_utils.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// Rotating one end face of a free bar by 90° (static, 4 load steps) must carry the whole bar
/// along rigidly: zero elastic energy, zero reaction, and positions equal to the rigid rotation.
class RigidRotation : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(RigidRotation, EndFaceRotationMovesTheBodyRigidly) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 0.3, 0.3), {4, 1, 1});
  Material material;
  material.model = GetParam();
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  DirichletSpec twist;
  twist.name = "rotation[0]";
  twist.kind = DirichletKind::rotation;
  twist.region = PlaneRegion{Vector3d(0, 0, 0), Vector3d(1, 0, 0), 0.0};
  twist.axis = Vector3d(0, 1, 1);
  twist.angle = M_PI / 2;
  twist.has_center = true;
  twist.center = Vector3d(0, 0.15, 0.15);
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 4;
  Simulation sim(mesh, {.material = material, .dirichlet = {twist}}, settings);
  while (!sim.finished())
    sim.advance();

  const Eigen::AngleAxisd rotation(M_PI / 2, twist.axis.normalized());
  const VectorXd& x = sim.positions();
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d X = mesh.vertices.row(v).transpose();
    const Vector3d expected = twist.center + rotation * (X - twist.center);
    EXPECT_LT((x.segment<3>(3 * v) - expected).norm(), 1e-8) << "vertex " << v;
  }
  // Energy scale for comparison: E · volume = 1e5 · 0.09 J.
  EXPECT_LT(sim.elastic_energy(), 1e-12 * 1e5 * 0.09);
  EXPECT_LT(sim.reactions()[0].force.norm(), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(SimPhysics, RigidRotation, ::testing::ValuesIn(testing::kAllModels),
                         [](const auto& info) { return to_string(info.param); });

}  // namespace
}  // namespace strata
