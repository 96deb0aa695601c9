#include <gtest/gtest.h>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

GroundPlane tilted_ground() {
  GroundPlane ground;
  ground.point = Vector3d(0.1, -0.2, 0.05);
  ground.normal = Vector3d(0.2, -0.1, 1.0);  // not unit length on purpose
  return ground;
}

TEST(SimGroundContact, PenaltyGradientAndHessianMatchFiniteDifferences) {
  const GroundPlane ground = tilted_ground();
  const double k = 37.0;
  // Six vertices, some below the plane; none within 1e-3 of it (away from the kink).
  VectorXd x(18);
  x << 0.3, 0.1, -0.4, 0.0, 0.0, 0.5, -0.2, 0.4, -0.1, 0.5, 0.5, 0.3, 0.7, -0.3, -0.6, 0.2, 0.2,
      0.0;
  VectorXd gradient = VectorXd::Zero(18);
  add_ground_penalty_gradient(ground, k, x, gradient);
  const double h = 1e-6;
  for (Index i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const double fd =
        (ground_penalty_energy(ground, k, xp) - ground_penalty_energy(ground, k, xm)) / (2 * h);
    EXPECT_NEAR(gradient[i], fd, 1e-7 * (1 + std::abs(fd))) << "dof " << i;
  }
  EXPECT_GT(ground_penalty_energy(ground, k, x), 0.0);
  // Hessian: the pattern needs every vertex's diagonal block.
  SparseMatrixd H(18, 18);
  for (int v = 0; v < 6; ++v)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        H.insert(3 * v + r, 3 * v + c) = 0.0;
  H.makeCompressed();
  add_ground_penalty_hessian(ground, k, x, H);
  const Eigen::MatrixXd dense = H;
  for (Index i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    VectorXd gp = VectorXd::Zero(18), gm = VectorXd::Zero(18);
    add_ground_penalty_gradient(ground, k, xp, gp);
    add_ground_penalty_gradient(ground, k, xm, gm);
    const VectorXd fd = (gp - gm) / (2 * h);
    EXPECT_LT((dense.col(i) - fd).norm(), 1e-6 * (1 + fd.norm())) << "dof " << i;
  }
}

TEST(SimGroundContact, ProjectionRemovesInwardVelocityAndAppliesCoulombFriction) {
  GroundPlane ground;  // z = 0
  ground.friction = 0.5;
  VectorXd x(6), v(6);
  x << 0, 0, -0.01, 1, 1, 0.2;  // first vertex below, second above
  v << 2.0, 0, -1.0, 3, 0, -5;
  project_ground_contact(ground, x, v, {});
  EXPECT_DOUBLE_EQ(x[2], 0.0);
  EXPECT_DOUBLE_EQ(v[2], 0.0);
  EXPECT_DOUBLE_EQ(v[0], 2.0 - 0.5 * 1.0);  // tangential speed reduced by μ |Δv_n|
  EXPECT_EQ(x.tail<3>(), Vector3d(1, 1, 0.2));
  EXPECT_EQ(v.tail<3>(), Vector3d(3, 0, -5));
  // Friction never reverses the sliding direction.
  x << 0, 0, -0.01, 1, 1, 0.2;
  v << 0.1, 0, -1.0, 3, 0, -5;
  project_ground_contact(ground, x, v, {});
  EXPECT_DOUBLE_EQ(v[0], 0.0);
}

Material soft_material() {
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 2e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

TEST(SimGroundContact, DroppedCubeStaysAboveTheGround) {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0.05), Vector3d(0.1, 0.1, 0.15), {2, 2, 2});
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 2e-3;
  settings.duration = 0.4;
  GroundPlane ground;
  ground.friction = 0.3;
  Simulation sim(mesh,
                 {.material = soft_material(), .gravity = Vector3d(0, 0, -9.81), .ground = ground},
                 settings);
  double min_z_seen = 1.0;
  while (!sim.finished()) {
    sim.advance();
    for (Index v = 0; v < sim.positions().size() / 3; ++v)
      min_z_seen = std::min(min_z_seen, sim.positions()[3 * v + 2]);
  }
  EXPECT_GE(min_z_seen, 0.0);
  // It fell (free fall to the ground takes √(2·0.05/9.81) ≈ 0.10 s) and rests on the ground.
  EXPECT_LT(min_z_seen, 1e-12);
  Vector3d centroid = Vector3d::Zero();
  for (Index v = 0; v < sim.positions().size() / 3; ++v)
    centroid += sim.positions().segment<3>(3 * v);
  centroid /= static_cast<double>(sim.positions().size() / 3);
  EXPECT_NEAR(centroid.z(), 0.05, 0.005);
}

// Mean horizontal velocity of a cube sliding on the ground after `duration` seconds.
double slide(double friction, double duration) {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.1, 0.1, 0.1), {2, 2, 2});
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 1e-3;
  settings.duration = duration;
  GroundPlane ground;
  ground.friction = friction;
  Simulation sim(mesh,
                 {.material = soft_material(), .gravity = Vector3d(0, 0, -9.81), .ground = ground},
                 settings);
  VectorXd v = VectorXd::Zero(sim.velocities().size());
  for (Index i = 0; i < v.size() / 3; ++i)
    v[3 * i] = 1.0;
  sim.set_state(sim.positions(), v);
  while (!sim.finished())
    sim.advance();
  double momentum = 0.0;
  for (Index i = 0; i < v.size() / 3; ++i)
    momentum += sim.vertex_mass()[i] * sim.velocities()[3 * i];
  return momentum / sim.vertex_mass().sum();
}

TEST(SimGroundContact, FrictionSlowsSlidingAtCoulombRate) {
  const double duration = 0.15;
  const double frictionless = slide(0.0, duration);
  const double with_friction = slide(0.4, duration);
  EXPECT_NEAR(frictionless, 1.0, 1e-6);
  // Coulomb: the contact impulses carry the weight, so the body decelerates at μ g on average.
  const double expected = 1.0 - 0.4 * 9.81 * duration;
  EXPECT_NEAR(with_friction, expected, 0.1 * (1.0 - expected));
}

}  // namespace
}  // namespace strata
