// von Mises plasticity (plasticity.hpp): the return mapping of one element against its defining
// properties, and bars in uniaxial tension against the closed-form response of the
// logarithmic-strain model (plateau, hardening slope, elastic unloading, permanent set).
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <random>

#include "fem_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/fem/plasticity.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

using testing::random_rotation;

constexpr double kE = 1e7, kNu = 0.3, kYield = 1e4;
constexpr double kLength = 1.0, kWidth = 0.2;

Material plastic_material(MaterialModel model, double hardening) {
  Material material;
  material.model = model;
  material.youngs_modulus = kE;
  material.poisson_ratio = kNu;
  material.plasticity = Plasticity{kYield, hardening};
  return material;
}

TEST(PlasticReturn, BelowYieldNothingFlows) {
  const LameParameters lame = lame_parameters(kE, kNu);
  Matrix3d F = Matrix3d::Identity();
  F(0, 0) = 1.0 + 0.5 * kYield / kE;
  const ElementReturn r = return_map(F, Matrix3d::Identity(), 0.0, lame, {kYield, 0.0});
  EXPECT_FALSE(r.yielded);
  EXPECT_EQ(r.equivalent_strain, 0.0);
  EXPECT_EQ(r.plastic_inverse, Matrix3d::Identity());
}

TEST(PlasticReturn, PutsTheStressOnTheYieldSurfaceIsochorically) {
  std::mt19937 rng(7);
  const LameParameters lame = lame_parameters(kE, kNu);
  for (double hardening : {0.0, 1e6}) {
    for (int trial = 0; trial < 50; ++trial) {
      const Matrix3d R = random_rotation(rng);
      std::uniform_real_distribution<double> strain(-0.02, 0.02);
      const Vector3d stretch(1 + strain(rng), 1 + strain(rng), 1 + strain(rng));
      const Matrix3d F = R * stretch.asDiagonal() * random_rotation(rng).transpose();
      const double start_strain = 0.001 * trial / 50.0;
      const Matrix3d start_inverse = Matrix3d::Identity();
      const ElementReturn r = return_map(F, start_inverse, start_strain, lame, {kYield, hardening});
      const double q_trial = hencky_equivalent_stress(F * start_inverse, lame);
      const double yield_before = kYield + hardening * start_strain;
      ASSERT_EQ(r.yielded, q_trial > yield_before) << trial;
      if (!r.yielded) continue;
      const double q = hencky_equivalent_stress(F * r.plastic_inverse, lame);
      const double yield_after = kYield + hardening * r.equivalent_strain;
      EXPECT_NEAR(q, yield_after, 1e-9 * yield_after) << trial;
      EXPECT_NEAR(r.plastic_inverse.determinant(), 1.0, 1e-12) << trial;
      // Radial return: Δε̄ = (q_trial − yield) / (3μ + H).
      EXPECT_NEAR(r.equivalent_strain - start_strain,
                  (q_trial - yield_before) / (3 * lame.mu + hardening), 1e-12)
          << trial;
      // The elastic part keeps the trial's principal directions and volume.
      EXPECT_NEAR((F * r.plastic_inverse).determinant(), F.determinant(), 1e-12) << trial;
    }
  }
}

TEST(PlasticReturn, StopsAtTheStrainCap) {
  const LameParameters lame = lame_parameters(kE, kNu);
  Matrix3d F = Matrix3d::Identity();
  F(0, 0) = 1.02;
  Plasticity capped{kYield, 0.0, 0.004};
  const ElementReturn r = return_map(F, Matrix3d::Identity(), 0.001, lame, capped);
  EXPECT_TRUE(r.yielded);
  EXPECT_DOUBLE_EQ(r.equivalent_strain, 0.004);
  const ElementReturn at_cap = return_map(F, r.plastic_inverse, 0.004, lame, capped);
  EXPECT_FALSE(at_cap.yielded);
}

TEST(PlasticReturn, InvertedTrialStatesDoNotFlow) {
  const LameParameters lame = lame_parameters(kE, kNu);
  Matrix3d F = Matrix3d::Identity();
  F(2, 2) = -0.5;
  EXPECT_FALSE(return_map(F, Matrix3d::Identity(), 0.0, lame, {kYield, 0.0}).yielded);
}

TEST(PlasticReturn, InvalidParametersAreRejected) {
  EXPECT_THROW(validate_plasticity({0.0, 0.0}, "material.plasticity"), InputError);
  EXPECT_THROW(validate_plasticity({1e4, -1.0}, "material.plasticity"), InputError);
  EXPECT_THROW(validate_plasticity({1e4, 0.0, 0.0}, "material.plasticity"), InputError);
  Material material;
  material.plasticity = Plasticity{-1.0, 0.0};
  EXPECT_THROW(validate_material(material, "material"), InputError);
}

/// A bar [0, L] × [0, W]² on the symmetry planes y = 0, z = 0 and x = 0 (one component each), so
/// the stress is exactly uniaxial and uniform. A vertex on two planes belongs to the later group
/// (dirichlet.hpp); the uniform solution meets the constraint it loses there anyway.
struct UniaxialBar {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(kLength, kWidth, kWidth), {6, 2, 2});
  std::vector<DirichletSpec> symmetry() const {
    std::vector<DirichletSpec> groups;
    for (int axis : {1, 2, 0}) {
      DirichletSpec spec;
      spec.name = "symmetry[" + std::to_string(axis) + "]";
      spec.region = PlaneRegion{Vector3d::Zero(), Vector3d::Unit(axis), 0.0};
      spec.components = {axis == 0, axis == 1, axis == 2};
      groups.push_back(spec);
    }
    return groups;
  }
  /// The end face x = L pulled to `strains` yield strains along x (x only).
  DirichletSpec pull(double strains) const {
    DirichletSpec spec;
    spec.name = "prescribed[0]";
    spec.region = PlaneRegion{Vector3d(kLength, 0, 0), Vector3d::UnitX(), 0.0};
    spec.kind = DirichletKind::displacement;
    spec.displacement = Vector3d(strains * kYield / kE * kLength, 0, 0);
    spec.components = {true, false, false};
    return spec;
  }
  /// Mean x displacement of the end face x = L.
  double end_displacement(const Simulation& sim) const {
    double sum = 0.0;
    int count = 0;
    for (Index v = 0; v < mesh.vertices.rows(); ++v) {
      if (mesh.vertices(v, 0) < kLength - 1e-12) continue;
      sum += sim.positions()[3 * v] - kLength;
      ++count;
    }
    return sum / count;
  }
};

/// Closed form of the logarithmic-strain model in uniaxial tension under the nominal stress s
/// (force over the rest area) beyond yield, H > 0: the Kirchhoff stress τ = E εₑ = σ_y + H εₚ,
/// and τ = J σ = s exp(εₑ + εₚ) (the cross-section shrinks by exp(−2ν εₑ − εₚ)). The fixed point
/// τ = s exp(τ/E + (τ − σ_y)/H) contracts by τ (1/E + 1/H) ≪ 1. Returns εₚ.
double uniaxial_plastic_strain(double nominal_stress, double hardening) {
  double tau = nominal_stress;
  for (int i = 0; i < 100; ++i)
    tau = nominal_stress * std::exp(tau / kE + (tau - kYield) / hardening);
  return (tau - kYield) / hardening;
}

class UniaxialPlateau : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(UniaxialPlateau, PerfectPlasticityHoldsTheYieldStress) {
  const UniaxialBar bar;
  std::vector<DirichletSpec> groups = bar.symmetry();
  groups.push_back(bar.pull(5.0));
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 10;
  Simulation sim(bar.mesh, {.material = plastic_material(GetParam(), 0.0), .dirichlet = groups},
                 settings);
  while (!sim.finished()) {
    sim.advance();
    const double strain = std::log1p(bar.end_displacement(sim) / kLength);
    const TetFields fields = sim.model().tet_fields(sim.positions());
    for (Index t = 0; t < fields.von_mises.size(); ++t) {
      if (strain > 1.2 * kYield / kE) {
        EXPECT_NEAR(fields.von_mises[t], kYield, 0.01 * kYield) << "step " << sim.step_count();
      } else if (strain < 0.9 * kYield / kE) {
        EXPECT_NEAR(fields.von_mises[t], kE * strain, 0.01 * kE * strain);
      }
    }
  }
  const SimulationCounters counters = sim.counters();
  EXPECT_EQ(counters.plastic_unconverged_steps, 0);
  EXPECT_EQ(counters.yielded_tets, bar.mesh.tets.rows());
  // Total strain 5 ε_y: about 4 ε_y of it is plastic.
  const double expected = std::log1p(5 * kYield / kE) - kYield / kE;
  for (Index t = 0; t < bar.mesh.tets.rows(); ++t)
    EXPECT_NEAR(sim.plastic_state().equivalent_strain[t], expected, 0.02 * expected);
}

INSTANTIATE_TEST_SUITE_P(AllModels, UniaxialPlateau, ::testing::ValuesIn(testing::kAllModels),
                         [](const auto& info) { return to_string(info.param); });

/// The bar pulled by a total force P·s(λ) on its end face, loaded and unloaded by the amplitude.
struct ForceCycle {
  double peak_end_displacement = 0.0;
  double final_end_displacement = 0.0;
  double final_plastic_strain = 0.0;
  long unconverged = 0;
};

ForceCycle force_cycle(double peak_nominal_stress, double hardening) {
  const UniaxialBar bar;
  RegionLoad pull{"forces[0]", PlaneRegion{Vector3d(kLength, 0, 0), Vector3d::UnitX(), 0.0},
                  Vector3d(peak_nominal_stress * kWidth * kWidth, 0, 0)};
  pull.amplitude.points = {{0.0, 0.0}, {0.5, 1.0}, {1.0, 0.0}};
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 20;
  Simulation sim(bar.mesh,
                 {.material = plastic_material(MaterialModel::neohookean, hardening),
                  .dirichlet = bar.symmetry(),
                  .loads = {pull}},
                 settings);
  ForceCycle cycle;
  while (!sim.finished()) {
    sim.advance();
    cycle.peak_end_displacement = std::max(cycle.peak_end_displacement, bar.end_displacement(sim));
  }
  cycle.final_end_displacement = bar.end_displacement(sim);
  cycle.final_plastic_strain = sim.plastic_state().equivalent_strain.maxCoeff();
  cycle.unconverged = sim.counters().plastic_unconverged_steps;
  return cycle;
}

TEST(UniaxialCycle, BelowYieldTheBarReturnsToRest) {
  const ForceCycle cycle = force_cycle(0.8 * kYield, 0.0);
  EXPECT_NEAR(cycle.peak_end_displacement, 0.8 * kYield / kE * kLength,
              0.01 * kLength * kYield / kE);
  EXPECT_EQ(cycle.final_plastic_strain, 0.0);
  EXPECT_LT(std::abs(cycle.final_end_displacement), 1e-6 * cycle.peak_end_displacement);
}

TEST(UniaxialCycle, BeyondYieldTheBarKeepsThePermanentSetOfTheHardeningLaw) {
  const double hardening = 0.1 * kE;
  const double peak = 1.5 * kYield;
  const ForceCycle cycle = force_cycle(peak, hardening);
  EXPECT_EQ(cycle.unconverged, 0);
  const double plastic = uniaxial_plastic_strain(peak, hardening);
  ASSERT_GT(plastic, 0.0);
  EXPECT_NEAR(cycle.final_plastic_strain, plastic, 0.02 * plastic);
  // Unloaded, the elastic part is gone: the length is L exp(εₚ).
  const double set = kLength * std::expm1(plastic);
  EXPECT_NEAR(cycle.final_end_displacement, set, 0.02 * set);
  EXPECT_GT(cycle.peak_end_displacement, cycle.final_end_displacement);
}

TEST(UniaxialCycle, HardeningSlopeFollowsTheTangentModulus) {
  // Beyond yield, dσ/dε = E H / (E + H) (small strain): two peaks give the slope.
  const double hardening = 0.2 * kE;
  const double p1 = 1.2 * kYield, p2 = 1.6 * kYield;
  const double e1 = force_cycle(p1, hardening).peak_end_displacement / kLength;
  const double e2 = force_cycle(p2, hardening).peak_end_displacement / kLength;
  const double tangent = kE * hardening / (kE + hardening);
  EXPECT_NEAR((p2 - p1) / (e2 - e1), tangent, 0.02 * tangent);
}

TEST(UniaxialDynamic, ImplicitStepsHoldThePlateau) {
  // Backward Euler, a slow pull with heavy mass damping: quasi-static, so the stress plateaus.
  const UniaxialBar bar;
  std::vector<DirichletSpec> groups = bar.symmetry();
  groups.push_back(bar.pull(3.0));
  Material material = plastic_material(MaterialModel::neohookean, 0.0);
  material.density = 10.0;
  material.mass_damping = 50.0;
  SolverSettings settings;
  settings.dt = 0.02;
  settings.duration = 1.0;
  Simulation sim(bar.mesh, {.material = material, .dirichlet = groups}, settings);
  while (!sim.finished())
    sim.advance();
  const TetFields fields = sim.model().tet_fields(sim.positions());
  for (Index t = 0; t < fields.von_mises.size(); ++t)
    EXPECT_NEAR(fields.von_mises[t], kYield, 0.01 * kYield);
  EXPECT_EQ(sim.counters().plastic_unconverged_steps, 0);
  EXPECT_GT(sim.counters().plastic_passes, sim.counters().steps);  // steps were repeated
}

}  // namespace
}  // namespace strata
