// The recovery error estimate: zero for affine fields (any cut) and on the finest level, large at
// a kink of the displacement field and under a concentrated load, and falling as a uniform cut is
// refined towards the finest level.
#include <gtest/gtest.h>

#include <cmath>

#include "refinement_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/hierarchy/refinement_recovery_estimator.hpp"

namespace strata {
namespace {

using test::make_snapshot;
using test::mixed_cut;
using test::node_centroid;
using test::slab;
using test::test_material;

/// Uniaxial strain switching from 0 to 1 % across the plane x = 0.4: a strain jump there.
Vector3d kink(const Vector3d& X) {
  return Vector3d(0.01 * std::max(0.0, X.x() - 0.4), 0, 0);
}

TEST(RecoveryEstimator, ZeroForAffineFieldsOnAMixedCut) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = mixed_cut(tree);
  Matrix3d G;
  G << 0.01, 0.002, -0.003, 0.001, -0.004, 0.002, 0.0, 0.003, 0.006;
  const auto affine = [&](const Vector3d& X) -> Vector3d { return G * X + Vector3d(1, 2, 3); };
  const test::CutSnapshot s = make_snapshot(cut, test_material(), affine, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  EXPECT_GT(estimate.solution_energy_sq, 0.0);
  EXPECT_LE(estimate.relative_error, 1e-9);
  EXPECT_LE(estimate.element_error_sq.maxCoeff(), 1e-18 * estimate.solution_energy_sq);
}

TEST(RecoveryEstimator, ZeroOnTheFinestLevel) {
  TetTree tree(slab(), 1);
  const ActiveCut cut = ActiveCut::uniform(tree, 1);
  const auto bend = [](const Vector3d& X) -> Vector3d {
    return Vector3d(0, 0, 0.01 * X.x() * X.x());
  };
  const test::CutSnapshot s = make_snapshot(cut, test_material(), bend, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  EXPECT_EQ(estimate.relative_error, 0.0);
  EXPECT_GT(estimate.relative_energy_error, 0.0);  // against the exact solution it is not zero
}

TEST(RecoveryEstimator, PeaksAtAKinkOfTheField) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 0);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  EXPECT_GT(estimate.upper_error, 0.05);
  EXPECT_GT(estimate.load_work_error, 0.0);
  EXPECT_NEAR(estimate.relative_error, std::sqrt(estimate.upper_error * estimate.load_work_error),
              1e-15);
  Index peak = 0;
  estimate.element_error_sq.maxCoeff(&peak);
  EXPECT_NEAR(node_centroid(tree, s.cut.flat.tet_nodes[peak]).x(), 0.4, 1.0 / 6.0 + 1e-12);
  for (Index t = 0; t < estimate.element_error_sq.size(); ++t)
    if (std::abs(node_centroid(tree, s.cut.flat.tet_nodes[t]).x() - 0.4) > 0.4) {
      EXPECT_LE(estimate.element_error_sq[t], 1e-12 * estimate.element_error_sq[peak]);
    }
}

TEST(RecoveryEstimator, FallsAsAUniformCutIsRefined) {
  TetTree tree(slab(), 3);
  const auto bump = test::bump(Vector3d(0.5, 0.5, 0.25), 0.3, 0.01);
  double previous = 1e300;
  for (int level = 0; level < 3; ++level) {
    const ActiveCut cut = ActiveCut::uniform(tree, level);
    const test::CutSnapshot s = make_snapshot(cut, test_material(), bump, {});
    const double error = recovery_error_estimate(s.state()).relative_error;
    EXPECT_LT(error, previous) << "level " << level;
    previous = error;
  }
}

TEST(RecoveryIndicator, MarksTetsAboveTheirShareOfTheTolerance) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 0);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  VectorXd eta;
  RecoveryIndicator(0.01).evaluate(s.state(), eta);
  ASSERT_EQ(eta.size(), estimate.element_error_sq.size());
  // Σ η̂² = N (z/τ_z)² with τ_z = (τ² z² / c)^⅓, i.e. N (e/τ)^{4/3}: the tets' shares of the
  // tolerance on the upper estimate add up to it.
  const double n = static_cast<double>(eta.size());
  const double z = estimate.upper_error;
  const double upper_tolerance = std::cbrt(0.01 * 0.01 * z * z / estimate.load_work_error);
  EXPECT_NEAR(eta.squaredNorm() / n, std::pow(estimate.upper_error / upper_tolerance, 2),
              1e-9 * eta.squaredNorm() / n);
  EXPECT_NEAR(eta.squaredNorm() / n, std::pow(estimate.relative_error / 0.01, 4.0 / 3.0),
              1e-9 * eta.squaredNorm() / n);
  EXPECT_GT(eta.maxCoeff(), 1.0);
  EXPECT_THROW(RecoveryIndicator(0.0), InputError);
  EXPECT_THROW(RecoveryIndicator(1.0), InputError);
}

}  // namespace
}  // namespace strata
