// Surface springs (surface_springs.hpp): forces and Hessian against finite differences of the
// energy, rest under rigid motion, the yield rule, and a cantilever bent beyond the springs'
// yield strain that keeps a permanent set while one with elastic springs returns to rest.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/core/sim/surface_springs.hpp"

namespace strata {
namespace {

struct Block {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 0.5, 0.4), {3, 2, 2});
  MatrixX3i boundary = boundary_faces(mesh.tets);
};

TEST(SurfaceSprings, SparseSubsetOfBoundaryEdgesReproducibleBySeed) {
  const Block block;
  const SurfaceSprings all(block.mesh.vertices, block.boundary, {1e6, 0.01, 1.0, 3});
  const SurfaceSprings half(block.mesh.vertices, block.boundary, {1e6, 0.01, 0.5, 3});
  const SurfaceSprings again(block.mesh.vertices, block.boundary, {1e6, 0.01, 0.5, 3});
  EXPECT_LT(half.size(), all.size());
  EXPECT_GT(half.size(), 0);
  EXPECT_EQ(half.edges(), again.edges());
  for (Index s = 0; s < all.size(); ++s) {
    const auto [a, b] = all.edges()[s];
    const double length = (block.mesh.vertices.row(b) - block.mesh.vertices.row(a)).norm();
    EXPECT_DOUBLE_EQ(all.rest_lengths()[s], length);
    EXPECT_DOUBLE_EQ(all.stiffness()[s], 1e6 * length);
  }
}

TEST(SurfaceSprings, ForcesAndHessianAreDerivativesOfTheEnergy) {
  const Block block;
  const SurfaceSprings springs(block.mesh.vertices, block.boundary, {1e6, 0.01, 0.7, 5});
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.03);
  VectorXd x = flatten(block.mesh.vertices);
  for (Index i = 0; i < x.size(); ++i)
    x[i] += noise(rng);
  VectorXd f = VectorXd::Zero(x.size());
  springs.add_forces(x, f);
  const double h = 1e-6;
  for (Index i = 0; i < x.size(); i += 5) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const double dE = (springs.energy(xp) - springs.energy(xm)) / (2 * h);
    EXPECT_NEAR(-f[i], dE, 1e-6 * (std::abs(dE) + 1.0)) << i;
  }
  ElasticModel model(block.mesh.vertices, block.mesh.tets, Material{});
  SparseMatrixd H = model.stiffness_pattern();
  const Index nonzeros = H.nonZeros();
  springs.add_hessian(x, H, false);
  EXPECT_EQ(H.nonZeros(), nonzeros);  // boundary edges are tet edges: the pattern holds them
  const Eigen::MatrixXd dense(H);
  for (Index j = 0; j < x.size(); j += 7) {
    VectorXd xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    VectorXd fp = VectorXd::Zero(x.size()), fm = VectorXd::Zero(x.size());
    springs.add_forces(xp, fp);
    springs.add_forces(xm, fm);
    const VectorXd column = -(fp - fm) / (2 * h);
    EXPECT_LE((dense.col(j) - column).norm(), 1e-5 * (column.norm() + 1.0)) << j;
  }
  SparseMatrixd projected = model.stiffness_pattern();
  springs.add_hessian(x, projected, true);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen((Eigen::MatrixXd(projected)));
  EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-6 * eigen.eigenvalues().maxCoeff());
}

TEST(SurfaceSprings, RigidMotionLeavesEverySpringAtRest) {
  const Block block;
  SurfaceSprings springs(block.mesh.vertices, block.boundary, {1e6, 0.01, 1.0, 1});
  const Matrix3d R = Eigen::AngleAxisd(0.8, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  MatrixX3d moved =
      (block.mesh.vertices * R.transpose()).rowwise() + Vector3d(4, -2, 1).transpose();
  const VectorXd x = flatten(moved);
  EXPECT_LT(springs.energy(x), 1e-20);
  VectorXd f = VectorXd::Zero(x.size());
  springs.add_forces(x, f);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_EQ(springs.yield(x), 0);
}

TEST(SurfaceSprings, RestLengthsFollowBeyondTheYieldStrain) {
  const Block block;
  SurfaceSprings springs(block.mesh.vertices, block.boundary, {1e6, 0.01, 1.0, 1});
  MatrixX3d stretched = block.mesh.vertices;
  stretched.col(0) *= 1.005;  // below yield along x
  EXPECT_EQ(springs.yield(flatten(stretched)), 0);
  stretched = block.mesh.vertices;
  stretched.col(0) *= 1.03;  // 3 % along x: edges mostly along x yield
  const VectorXd x = flatten(stretched);
  const Index yielded = springs.yield(x);
  EXPECT_GT(yielded, 0);
  for (Index s = 0; s < springs.size(); ++s) {
    const auto [a, b] = springs.edges()[s];
    const double length = (x.segment<3>(3 * b) - x.segment<3>(3 * a)).norm();
    EXPECT_LE(length / springs.rest_lengths()[s] - 1.0, 0.01 + 1e-12);
  }
  EXPECT_NEAR(springs.largest_plastic_strain(), std::log(1.03 / 1.01), 1e-9);
  EXPECT_THROW(validate_surface_springs({0.0, 0.01, 1.0, 1}, "s"), InputError);
  EXPECT_THROW(validate_surface_springs({1e6, 0.01, 1.5, 1}, "s"), InputError);
  EXPECT_THROW(validate_surface_springs({1e6, -1.0, 1.0, 1}, "s"), InputError);
}

/// Tip z displacement of a cantilever with surface springs after a tip load is applied and taken
/// away (static, 12 load steps): {at the peak, at the end}.
std::pair<double, double> spring_cantilever(double yield_strain) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 0.1, 0.1), {10, 2, 2});
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 1e7;
  DirichletSpec clamp;
  clamp.name = "fixed";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  RegionLoad tip{"tip", PlaneRegion{Vector3d(1, 0, 0), Vector3d::UnitX(), 0.0},
                 Vector3d(0, 0, -40.0)};
  tip.amplitude.points = {{0.0, 0.0}, {0.5, 1.0}, {1.0, 0.0}};
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 12;
  SimulationOptions options;
  options.surface_springs = SurfaceSpringSettings{5e7, yield_strain, 0.5, 2};
  Simulation sim(mesh, {.material = material, .dirichlet = {clamp}, .loads = {tip}}, settings,
                 std::move(options));
  double peak = 0.0;
  const auto tip_z = [&]() {
    double sum = 0.0;
    int count = 0;
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      if (mesh.vertices(v, 0) > 1.0 - 1e-12) {
        sum += sim.positions()[3 * v + 2] - mesh.vertices(v, 2);
        ++count;
      }
    return sum / count;
  };
  while (!sim.finished()) {
    sim.advance();
    if (sim.step_count() == 6) peak = tip_z();
  }
  return {peak, tip_z()};
}

TEST(SurfaceSprings, YieldingSpringsKeepAPermanentSetElasticOnesDoNot) {
  const auto [elastic_peak, elastic_end] =
      spring_cantilever(std::numeric_limits<double>::infinity());
  ASSERT_LT(elastic_peak, 0.0);
  EXPECT_LT(std::abs(elastic_end), 1e-6 * std::abs(elastic_peak));
  const auto [plastic_peak, plastic_end] = spring_cantilever(2e-4);
  EXPECT_LT(plastic_peak, elastic_peak);        // yielding springs stiffen less
  EXPECT_LT(plastic_end, 0.05 * plastic_peak);  // still bent down by 5 % of the peak or more
  EXPECT_LT(plastic_end, 0.0);
  EXPECT_GT(plastic_end, plastic_peak);  // but springs back partly
}

}  // namespace
}  // namespace strata
