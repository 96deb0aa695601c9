#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cstdio>
#include <limits>
#include <random>

#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/divergence_check.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/core/sim/stable_time_step.hpp"

namespace strata {
namespace {

Material beam_material(MaterialModel model) {
  Material material;
  material.model = model;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

/// A free 1 × 0.2 × 0.2 beam released from a 1% uniaxial stretch with the matching lateral
/// contraction (no gravity, no constraints): a longitudinal free oscillation of period
/// ≈ 2L/√(E/ρ) = 0.2 s.
struct FreeBeam {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 0.2, 0.2), {5, 1, 1});
  std::unique_ptr<Simulation> sim;

  FreeBeam(Integrator integrator, double dt_over_estimate, double duration,
           MaterialModel model = MaterialModel::corotated) {
    SolverSettings settings;
    settings.integrator = integrator;
    settings.duration = duration;
    // Probe the estimate with a throw-away instance (it depends on mesh and material only).
    settings.dt = 1.0;
    const double estimate =
        Simulation(mesh, {.material = beam_material(model)}, settings).stable_dt_estimate();
    settings.dt = dt_over_estimate * estimate;
    sim =
        std::make_unique<Simulation>(mesh, ProblemSpec{.material = beam_material(model)}, settings);
    VectorXd x = sim->positions();
    const double strain = 0.01, nu = beam_material(model).poisson_ratio;
    for (Index v = 0; v < x.size() / 3; ++v) {
      x[3 * v] += strain * (x[3 * v] - 0.5);
      x[3 * v + 1] -= nu * strain * (x[3 * v + 1] - 0.1);
      x[3 * v + 2] -= nu * strain * (x[3 * v + 2] - 0.1);
    }
    sim->set_state(x, VectorXd::Zero(x.size()));
  }
  double energy() const { return sim->kinetic_energy() + sim->elastic_energy(); }
};

/// Max relative deviation of kinetic + elastic energy from its initial value over the run.
double max_energy_drift(FreeBeam& beam) {
  const double e0 = beam.energy();
  double drift = 0.0;
  while (!beam.sim->finished()) {
    beam.sim->advance();
    drift = std::max(drift, std::abs(beam.energy() - e0) / e0);
  }
  return drift;
}

TEST(SimIntegrators, ExplicitIntegratorsConserveEnergyOfFreeOscillation) {
  FreeBeam euler(Integrator::symplectic_euler, 0.1, 2.0);
  FreeBeam rk4(Integrator::rk4, 0.1, 2.0);
  const double euler_drift = max_energy_drift(euler);
  const double rk4_drift = max_energy_drift(rk4);
  std::printf("steps %ld, symplectic Euler drift %.3e, RK4 drift %.3e\n", euler.sim->step_count(),
              euler_drift, rk4_drift);
  EXPECT_LT(euler_drift, 0.05);
  EXPECT_LT(rk4_drift, 1e-3);
  EXPECT_LT(rk4_drift, euler_drift);
}

/// Runs the beam to the end; returns the step at which divergence was detected, or -1.
long diverged_step(FreeBeam& beam) {
  try {
    while (!beam.sim->finished())
      beam.sim->advance();
  } catch (const DivergenceError& e) {
    return e.step();
  }
  return -1;
}

TEST(SimIntegrators, ForcesPreparedAfterAStepGiveTheSameTrajectory) {
  // Symplectic Euler with StVK computes the next step's forces after each step (with the
  // inversion check). A run whose state is re-set before every step (which drops them) must
  // follow the same trajectory bit for bit, through ground contact (projected after the step).
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0.02), Vector3d(0.2, 0.2, 0.22), {3, 3, 3});
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 1e5;
  GroundPlane ground;
  ground.point = Vector3d::Zero();
  ground.normal = Vector3d::UnitZ();
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.duration = 1.0;
  settings.dt = 1e-6;
  {
    const Simulation probe(
        mesh, {.material = material, .gravity = Vector3d(0, 0, -9.81), .ground = ground}, settings);
    settings.dt = 0.5 * probe.stable_dt_estimate();
  }
  Simulation prepared(
      mesh, {.material = material, .gravity = Vector3d(0, 0, -9.81), .ground = ground}, settings);
  Simulation fresh(mesh, {.material = material, .gravity = Vector3d(0, 0, -9.81), .ground = ground},
                   settings);
  bool touched = false;
  for (int step = 0; step < 4000 && !touched; ++step) {
    prepared.advance();
    fresh.set_state(fresh.positions(), fresh.velocities());
    fresh.advance();
    ASSERT_EQ(prepared.positions(), fresh.positions()) << "step " << step;
    ASSERT_EQ(prepared.velocities(), fresh.velocities()) << "step " << step;
    touched = prepared.positions().reshaped(3, Eigen::AutoSize).row(2).minCoeff() <= 1e-12;
  }
  EXPECT_TRUE(touched);  // the box reached the ground within the steps
  for (int step = 0; step < 200; ++step) {
    prepared.advance();
    fresh.set_state(fresh.positions(), fresh.velocities());
    fresh.advance();
  }
  EXPECT_EQ(prepared.positions(), fresh.positions());
  // The kept forces were used: one force evaluation per step instead of one plus the state's.
  EXPECT_LT(prepared.counters().element_evaluations, fresh.counters().element_evaluations);
}

/// ω_max of the lumped-mass system linearised at rest, from a dense eigen-solve of M^-½ K M^-½
/// with the elastic model's own stiffness.
double true_max_angular_frequency(const TetMesh& mesh, const Material& material) {
  const ElasticModel model(mesh.vertices, mesh.tets, material);
  SparseMatrixd K;
  model.stiffness(model.rest_positions(), K, false);
  const VectorXd mass = lumped_vertex_mass(model.rest_data().rest_volume, mesh.tets,
                                           model.num_vertices(), material.density);
  VectorXd inverse_sqrt_mass(model.num_dofs());
  for (Index i = 0; i < model.num_dofs(); ++i)
    inverse_sqrt_mass[i] = 1.0 / std::sqrt(mass[i / 3]);
  const Eigen::MatrixXd scaled =
      inverse_sqrt_mass.asDiagonal() * Eigen::MatrixXd(K) * inverse_sqrt_mass.asDiagonal();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled, Eigen::EigenvaluesOnly)
                       .eigenvalues()
                       .maxCoeff());
}

/// The 1 × 0.5 × 0.4 box of 4 × 2 × 2 cells with every vertex moved by up to 3 cm per axis.
TetMesh jittered_box(unsigned seed) {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 0.5, 0.4), {4, 2, 2});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      mesh.vertices(v, k) += jitter(rng);
  return mesh;
}

TEST(SimIntegrators, StableStepEstimateIsABoundOnTheTrueLimit) {
  // Independent check: the true highest frequency of the lumped-mass system linearised at rest,
  // from a dense generalised eigen-solve of K u = ω² M u on an irregular mesh.
  const TetMesh mesh = jittered_box(3);
  const Material material = beam_material(MaterialModel::stvk);
  const double omega_true = true_max_angular_frequency(mesh, material);
  const double omega_bound = max_angular_frequency_bound(mesh.vertices, mesh.tets, material);
  EXPECT_GE(omega_bound, omega_true);
  EXPECT_LT(omega_bound, 2.5 * omega_true);  // a useful bound, not an arbitrarily loose one
  std::printf("omega bound / true = %.3f\n", omega_bound / omega_true);
  EXPECT_NEAR(stable_time_step_estimate(mesh.vertices, mesh.tets, material, Integrator::rk4),
              2.0 * std::sqrt(2.0) / omega_bound, 1e-15 / omega_bound);
}

TEST(SimIntegrators, GroupedFrequencyBoundLiesBetweenTheTrueValueAndTheElementBound) {
  // Any partition of the tets bounds ω_max (stable_time_step.hpp); a whole mesh as one group is
  // its true ω_max, and larger groups bound it more tightly than single tets.
  for (const double nu : {0.3, 0.49}) {
    const TetMesh mesh = jittered_box(5);
    Material material = beam_material(MaterialModel::neohookean);
    material.poisson_ratio = nu;
    const double omega_true = true_max_angular_frequency(mesh, material);
    const double element = max_angular_frequency_bound(mesh.vertices, mesh.tets, material);
    const auto grouped = [&](Index size) {
      std::vector<int> groups(mesh.tets.rows());
      for (Index t = 0; t < mesh.tets.rows(); ++t)
        groups[t] = static_cast<int>(t / size);
      return max_angular_frequency_bound(mesh.vertices, mesh.tets, material, groups);
    };
    const double single = grouped(1), sixes = grouped(6), twenty_fours = grouped(24);
    const double slack = 1e-12 * omega_true;
    EXPECT_LE(single, element + slack);  // the exact element eigenvalue within its closed form
    EXPECT_LE(sixes, single + slack);
    EXPECT_LE(twenty_fours, sixes + slack);
    EXPECT_GE(twenty_fours, omega_true - slack);
    EXPECT_LT(twenty_fours, element);  // strictly tighter on these shapes
    std::printf("nu %.2f: omega bound / true: element %.3f, groups of 1 %.3f, 6 %.3f, 24 %.3f\n",
                nu, element / omega_true, single / omega_true, sixes / omega_true,
                twenty_fours / omega_true);
    // Tets on their own (−1) take the closed form, the others their groups'.
    std::vector<int> mixed(mesh.tets.rows(), -1);
    EXPECT_EQ(max_angular_frequency_bound(mesh.vertices, mesh.tets, material, mixed), element);
    // A mesh of at most 32 tets as one group: its true value, from an assembly of its own.
    const TetMesh small = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.5, 0.25, 0.2), {2, 2, 1});
    ASSERT_LE(small.tets.rows(), kMaxStabilityGroupTets);
    const std::vector<int> whole(small.tets.rows(), 7);
    const double whole_bound =
        max_angular_frequency_bound(small.vertices, small.tets, material, whole);
    EXPECT_NEAR(whole_bound, true_max_angular_frequency(small, material), 1e-10 * whole_bound);
  }
}

TEST(SimIntegrators, GroupedFrequencyBoundOfARegularTetIsTheClosedForm) {
  // A regular tet has G Gᵀ ∝ I, and the closed form's two inequalities are equalities there.
  MatrixX3d x(4, 3);
  x << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  const MatrixX4i tet = (MatrixX4i(1, 4) << 0, 1, 2, 3).finished();
  const Material material = beam_material(MaterialModel::stvk);
  const double closed = max_angular_frequency_bound(x, tet, material);
  const std::vector<int> own = {0};
  EXPECT_NEAR(max_angular_frequency_bound(x, tet, material, own), closed, 1e-12 * closed);
  EXPECT_NEAR(stable_time_step_estimate(x, tet, material, Integrator::rk4, own),
              2.0 * std::sqrt(2.0) / closed, 1e-12 / closed);
}

TEST(SimIntegrators, GroupedFrequencyBoundRejectsBadGroups) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {2, 2, 2});
  const Material material = beam_material(MaterialModel::stvk);
  const std::vector<int> short_list(mesh.tets.rows() - 1, 0);
  EXPECT_THROW(max_angular_frequency_bound(mesh.vertices, mesh.tets, material, short_list),
               std::invalid_argument);
  const std::vector<int> one_group(mesh.tets.rows(), 0);  // 48 tets
  EXPECT_THROW(max_angular_frequency_bound(mesh.vertices, mesh.tets, material, one_group),
               std::invalid_argument);
}

TEST(SimIntegrators, MeanEdgeLengthOfKuhnCubes) {
  // Every tet of a Kuhn-split cube of side h has three edges h, two face diagonals h√2 and one
  // body diagonal h√3. 40 × 40 × 10 cells: 96,000 tets, many blocks of the parallel sum.
  const double h = 0.025;
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 0.25), {40, 40, 10});
  ASSERT_EQ(mesh.tets.rows(), 96000);
  const double expected = h * (3.0 + 2.0 * std::sqrt(2.0) + std::sqrt(3.0)) / 6.0;
  double serial = 0.0, parallel = 0.0;
  {
    const ThreadLimit limit(1);
    serial = mean_edge_length(mesh.vertices, mesh.tets);
  }
  {
    const ThreadLimit limit(2);
    parallel = mean_edge_length(mesh.vertices, mesh.tets);
  }
  // Rounding bound of a sum of 6 · 96,000 terms: n ε relative.
  const double bound = 6.0 * 96000.0 * std::numeric_limits<double>::epsilon();
  EXPECT_NEAR(serial, expected, bound * expected);
  EXPECT_EQ(serial, parallel);  // the same sum for any number of threads
  EXPECT_EQ(mean_edge_length(mesh.vertices, MatrixX4i(0, 4)), 0.0);
}

TEST(SimIntegrators, MeanEdgeLengthAndFrequencyBoundOfAGradedMesh) {
  // Vertices moved so that every tet differs (x → x + 0.3 x², y → y (1 + 0.5 x)): the block sums
  // and the parallel maximum against plain loops over all 9,600 tets.
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 0.5), {20, 10, 8});
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const double x = mesh.vertices(v, 0);
    mesh.vertices(v, 0) = x + 0.3 * x * x;
    mesh.vertices(v, 1) *= 1.0 + 0.5 * x;
  }
  double sum = 0.0;
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        sum += (mesh.vertices.row(mesh.tets(t, a)) - mesh.vertices.row(mesh.tets(t, b))).norm();
  const double reference = sum / (6.0 * static_cast<double>(mesh.tets.rows()));
  EXPECT_NEAR(mean_edge_length(mesh.vertices, mesh.tets), reference, 1e-12 * reference);

  const Material material = beam_material(MaterialModel::stvk);
  const LameParameters lame = material.lame();
  double largest = 0.0;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    Matrix3d Dm;
    for (int k = 0; k < 3; ++k)
      Dm.col(k) =
          (mesh.vertices.row(mesh.tets(t, k + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
    const Matrix3d inverse = Dm.inverse();
    // Shape-function gradients: rows of Dm⁻¹ for corners 1–3, minus their sum for corner 0.
    Eigen::Matrix<double, 4, 3> G;
    G.bottomRows<3>() = inverse;
    G.row(0) = -inverse.colwise().sum();
    const Matrix3d GGt = G.transpose() * G;
    largest =
        std::max(largest, Eigen::SelfAdjointEigenSolver<Matrix3d>(GGt).eigenvalues().maxCoeff());
  }
  const double expected =
      std::sqrt(4.0 * (3.0 * lame.lambda + 2.0 * lame.mu) * largest / material.density);
  EXPECT_NEAR(max_angular_frequency_bound(mesh.vertices, mesh.tets, material), expected,
              1e-12 * expected);
}

TEST(SimIntegrators, ExplicitIntegratorsAreStableAtTheEstimate) {
  FreeBeam euler(Integrator::symplectic_euler, 1.0, 2.0);
  FreeBeam rk4(Integrator::rk4, 1.0, 2.0);
  EXPECT_EQ(diverged_step(euler), -1);
  EXPECT_EQ(diverged_step(rk4), -1);
}

TEST(SimIntegrators, Rk4BeyondTheStabilityLimitIsDetected) {
  FreeBeam beam(Integrator::rk4, 3.0, 2.0);
  const long diverged_at = diverged_step(beam);
  EXPECT_GT(diverged_at, 0);
  EXPECT_LT(diverged_at, 20);  // of 55 steps
}

TEST(SimIntegrators, DivergenceNamesTheVertexOrElementAndWhereItIsAtRest) {
  // The six tets of a unit cube: moving its corner (1, 1, 1) through the cube to (−1, −1, −1)
  // inverts tets around it (StVK checks inversion), and a far move trips the blow-up limit. Each
  // message gives the index and the rest position (an element's: its centroid).
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 1), {1, 1, 1});
  Material material;
  material.model = MaterialModel::stvk;
  const ElasticModel model(mesh.vertices, mesh.tets, material);
  const DivergenceLimits limits = default_divergence_limits(material, std::sqrt(3.0));
  VectorXd x = model.rest_positions();
  const Index corner = mesh.vertices.rows() - 1;  // (1, 1, 1)
  ASSERT_EQ(mesh.vertices.row(corner), Eigen::RowVector3d(1, 1, 1));
  const auto message = [&] {
    try {
      check_divergence(model, x, VectorXd(), limits, 3, 0.3, "static");
    } catch (const DivergenceError& error) {
      EXPECT_EQ(error.step(), 3);
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(), "");
  x.segment<3>(3 * corner) = Vector3d(-1, -1, -1);
  const std::string inverted = message();
  const auto [j, tet] = model.min_volume_ratio(x);
  ASSERT_LE(j, 0.0);
  Vector3d centroid = Vector3d::Zero();
  for (int k = 0; k < 4; ++k)
    centroid += 0.25 * mesh.vertices.row(mesh.tets(tet, k)).transpose();
  char expected[160];
  std::snprintf(expected, sizeof(expected),
                "static: step 3, t = 0.300000: element %d (at rest (%.4g, %.4g, %.4g) m) inverted",
                static_cast<int>(tet), centroid.x(), centroid.y(), centroid.z());
  EXPECT_EQ(inverted.rfind(expected, 0), 0u) << inverted;
  x.segment<3>(3 * corner) = Vector3d(1e3, 1, 1);
  EXPECT_EQ(message().rfind("static: step 3, t = 0.300000: vertex " + std::to_string(corner) +
                                " (at rest (1, 1, 1) m) displaced beyond the blow-up limit",
                            0),
            0u)
      << message();
}

TEST(SimIntegrators, BackwardEulerIsStableFarBeyondTheExplicitLimit) {
  FreeBeam beam(Integrator::implicit_euler, 100.0, 25.0, MaterialModel::neohookean);
  const double e0 = beam.energy();
  double max_energy = e0;
  while (!beam.sim->finished()) {
    beam.sim->advance();
    max_energy = std::max(max_energy, beam.energy());
  }
  std::printf("steps %ld, newton %ld, E0 %.3e, max %.3e, final %.3e\n", beam.sim->step_count(),
              beam.sim->counters().newton_iterations, e0, max_energy, beam.energy());
  // Backward Euler only dissipates: the energy never exceeds its initial value.
  EXPECT_LE(max_energy, e0 * (1 + 1e-9));
  EXPECT_LT(beam.energy(), e0);
}

}  // namespace
}  // namespace strata
