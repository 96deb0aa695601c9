// The recovery error estimate: zero for affine fields (any cut) and on the finest level, large at
// a kink of the displacement field and under a concentrated load, and falling as a uniform cut is
// refined towards the finest level. The budget on merges keeps the predicted estimate within it and
// predicts the estimate of the merged cut.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "refinement_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
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

TEST(RecoveryEstimator, TheLocalEstimateSeesAWeakLoadTheEnergyNormDilutes) {
  // A body-wide uniform strain (no recovery error, but most of the energy and the largest
  // displacement) plus a narrow bump of a tenth of that displacement: relative to the whole
  // body's energy the bump's error is diluted by about √(its width / the body's), relative to
  // the largest displacement it is not. The local term is zero for the uniform strain alone.
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 0);
  const auto uniform = [](const Vector3d& X) -> Vector3d { return Vector3d(0.01 * X.x(), 0, 0); };
  const auto narrow = test::bump(Vector3d(0.5, 0.5, 0.25), 0.15, 0.001);
  const auto both = [&](const Vector3d& X) -> Vector3d { return uniform(X) + narrow(X); };
  const RecoveryEstimate alone =
      recovery_error_estimate(make_snapshot(cut, test_material(), uniform, {}).state());
  EXPECT_LE(alone.local_error, 1e-12);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), both, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  EXPECT_GT(estimate.local_error, 3.0 * estimate.recovery_error);
  EXPECT_EQ(estimate.relative_error, estimate.local_error);
  // The largest local term is a tet the bump touches.
  Index peak = 0;
  estimate.element_local_error.maxCoeff(&peak);
  EXPECT_LT((node_centroid(tree, s.cut.flat.tet_nodes[peak]) - Vector3d(0.5, 0.5, 0.25)).norm(),
            0.15 + 1.0 / 3.0);
  // Relative to a larger displacement of the run so far, proportionally smaller.
  test::CutSnapshot scaled = make_snapshot(cut, test_material(), both, {});
  CutState state = scaled.state();
  state.solution_displacement_scale = 10.0 * estimate.reference_displacement;
  EXPECT_NEAR(recovery_error_estimate(state).local_error, 0.1 * estimate.local_error,
              1e-12 * estimate.local_error);
}

TEST(RecoveryEstimator, PeaksAtAKinkOfTheField) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 0);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  EXPECT_GT(estimate.upper_error, 0.05);
  EXPECT_GT(estimate.load_work_error, 0.0);
  EXPECT_NEAR(estimate.recovery_error, std::sqrt(estimate.upper_error * estimate.load_work_error),
              1e-15);
  EXPECT_EQ(estimate.relative_error, std::max(estimate.recovery_error, estimate.local_error));
  EXPECT_GT(estimate.local_error, 0.0);
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

TEST(RecoveryEstimator, TheSameBitsAtAnyThreadCount) {
  // A level-2 cut of 27,648 tets: many parallel tasks, whose terms are summed in tet order.
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 2);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const auto estimate_at = [&](int threads) {
    const ThreadLimit limit(threads);
    return recovery_error_estimate(s.state());
  };
  const RecoveryEstimate one = estimate_at(1);
  const RecoveryEstimate two = estimate_at(2);
  ASSERT_GT(one.relative_energy_error, 0.0);
  EXPECT_EQ(one.element_error_sq, two.element_error_sq);
  EXPECT_EQ(one.element_raw_error_sq, two.element_raw_error_sq);
  EXPECT_EQ(one.solution_energy_sq, two.solution_energy_sq);
  EXPECT_EQ(one.upper_error, two.upper_error);
  EXPECT_EQ(one.load_work_error, two.load_work_error);
  EXPECT_EQ(one.relative_energy_error, two.relative_energy_error);
}

TEST(RecoveryEstimator, TheCutsRestGeometryKeptByTheDriverGivesTheSameBits) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = mixed_cut(tree);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const RecoveryEstimate computed = recovery_error_estimate(s.state());
  const RecoveryGeometry geometry = recovery_geometry(s.cut.flat.mesh);
  CutState state = s.state();
  state.recovery_geometry = &geometry;
  const RecoveryEstimate kept = recovery_error_estimate(state);
  ASSERT_GT(computed.relative_error, 0.0);
  EXPECT_EQ(kept.element_error_sq, computed.element_error_sq);
  EXPECT_EQ(kept.element_local_error, computed.element_local_error);
  EXPECT_EQ(kept.relative_error, computed.relative_error);
  // The geometry of another cut is refused.
  const ActiveCut coarse = ActiveCut::uniform(tree, 0);
  const test::CutSnapshot other = make_snapshot(coarse, test_material(), kink, {});
  const RecoveryGeometry wrong = recovery_geometry(other.cut.flat.mesh);
  state.recovery_geometry = &wrong;
  EXPECT_THROW(recovery_error_estimate(state), std::logic_error);
}

TEST(RecoveryEstimator, EveryTetsTermsAsTheirDefinitionGivesThem) {
  // 3,463 tets: more than one parallel task of the terms, and not a multiple of the four tets the
  // terms are computed at a time. Reference: the definitions in the header, tet by tet.
  TetTree tree(slab(), 2);
  ActiveCut cut = ActiveCut::uniform(tree, 1);
  cut.refine(tree.child(7, 3));
  // Quadratic: no tet's strain is its vertices' recovered one, the last tets' included.
  const auto quadratic = [](const Vector3d& X) {
    return Vector3d(0.01 * X.x() * X.x(), 0.01 * X.x() * X.y(), 0.02 * X.z() * X.z());
  };
  const test::CutSnapshot s = make_snapshot(cut, test_material(), quadratic, {});
  const TetMesh& mesh = s.cut.flat.mesh;
  const Index num_tets = mesh.tets.rows();
  ASSERT_EQ(num_tets % 4, 3);
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  const auto& strain = s.fields.green_strain;
  const LameParameters lame = test_material().lame();
  const auto twice_psi = [&](const Vector6d& e) {
    const double trace = e[0] + e[1] + e[2];
    return 2.0 * lame.mu * (e.head<3>().squaredNorm() + 2.0 * e.tail<3>().squaredNorm()) +
           lame.lambda * trace * trace;
  };
  std::vector<double> volume(num_tets);
  Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(mesh.vertices.rows(), 7);
  for (Index t = 0; t < num_tets; ++t) {
    volume[t] = tet_signed_volume(mesh.vertices.row(mesh.tets(t, 0)).transpose(),
                                  mesh.vertices.row(mesh.tets(t, 1)).transpose(),
                                  mesh.vertices.row(mesh.tets(t, 2)).transpose(),
                                  mesh.vertices.row(mesh.tets(t, 3)).transpose());
    for (int k = 0; k < 4; ++k) {
      sums.row(mesh.tets(t, k)).head<6>() += volume[t] * strain.row(t);
      sums(mesh.tets(t, k), 6) += volume[t];
    }
  }
  const int depth = tree.max_level();
  VectorXd raw(num_tets), local(num_tets);
  for (Index t = 0; t < num_tets; ++t) {
    const Vector6d own = strain.row(t).transpose();
    Vector6d sum = Vector6d::Zero();
    double vertex_terms = 0.0, largest = 0.0;
    for (int k = 0; k < 4; ++k) {
      const Index v = mesh.tets(t, k);
      const Vector6d d = sums.row(v).head<6>().transpose() / sums(v, 6) - own;
      vertex_terms += twice_psi(d);
      sum += d;
      largest =
          std::max(largest, std::sqrt(d.head<3>().squaredNorm() + 2.0 * d.tail<3>().squaredNorm()));
    }
    raw[t] = volume[t] / 20.0 * (vertex_terms + twice_psi(sum));
    const int level = s.cut.flat.tet_levels[t];
    local[t] = (1.0 - std::ldexp(1.0, -(depth - level))) *
               std::cbrt(6.0 * std::sqrt(2.0) * std::abs(volume[t])) * largest;
  }
  // Relative to the largest term, and each of the last tets' to itself.
  ASSERT_GT(raw.maxCoeff(), 0.0);
  ASSERT_GT(local.maxCoeff(), 0.0);
  EXPECT_LE((estimate.element_raw_error_sq - raw).cwiseAbs().maxCoeff(), 1e-12 * raw.maxCoeff());
  EXPECT_LE((estimate.element_local_error - local).cwiseAbs().maxCoeff(), 1e-12 * local.maxCoeff());
  for (Index t = num_tets - 4; t < num_tets; ++t) {
    EXPECT_GT(raw[t], 1e-6 * raw.maxCoeff()) << "tet " << t;
    EXPECT_NEAR(estimate.element_raw_error_sq[t], raw[t], 1e-10 * raw[t]) << "tet " << t;
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
  // η_t = max(η̂_t, δ_t / (τ max|u|)). Σ η̂² = N (z/τ_z)² with τ_z = (τ² z² / c)^⅓, i.e.
  // N (√(zc)/τ)^{4/3}: the tets' shares of the tolerance on the upper estimate add up to it.
  const double n = static_cast<double>(eta.size());
  const double z = estimate.upper_error;
  const double upper_tolerance = std::cbrt(0.01 * 0.01 * z * z / estimate.load_work_error);
  const double share = upper_tolerance * upper_tolerance * estimate.reference_energy_sq / n;
  const VectorXd eta_upper = (estimate.element_error_sq / share).cwiseSqrt();
  const VectorXd eta_local =
      estimate.element_local_error / (0.01 * estimate.reference_displacement);
  for (Index t = 0; t < eta.size(); ++t)
    EXPECT_NEAR(eta[t], std::max(eta_upper[t], eta_local[t]), 1e-12 * eta[t]) << "tet " << t;
  EXPECT_NEAR(eta_upper.squaredNorm() / n, std::pow(estimate.upper_error / upper_tolerance, 2),
              1e-9 * eta_upper.squaredNorm() / n);
  EXPECT_NEAR(eta_upper.squaredNorm() / n, std::pow(estimate.recovery_error / 0.01, 4.0 / 3.0),
              1e-9 * eta_upper.squaredNorm() / n);
  // The local term marks exactly the tets whose δ_t exceeds τ max|u| (and no fewer).
  EXPECT_NEAR(eta_local.maxCoeff(), estimate.local_error / 0.01, 1e-12 * eta_local.maxCoeff());
  EXPECT_GT(eta.maxCoeff(), 1.0);
  EXPECT_THROW(RecoveryIndicator(0.0), InputError);
  EXPECT_THROW(RecoveryIndicator(1.0), InputError);
}

/// The roots of `tree`: on a uniform level-1 cut each one's eight children are active.
std::vector<NodeId> roots(const TetTree& tree) {
  std::vector<NodeId> nodes(static_cast<std::size_t>(tree.num_roots()));
  for (Index r = 0; r < tree.num_roots(); ++r)
    nodes[r] = static_cast<NodeId>(r);
  return nodes;
}

TEST(MergeBudget, PredictsTheEstimateOfTheMergedCut) {
  // Every root of a uniform level-1 cut merged: the prediction against the estimate of the same
  // displacement field on the level-0 cut. Smooth fields (a bump, a bending) and a strain jump.
  TetTree tree(slab(), 2);
  const auto bend = [](const Vector3d& X) -> Vector3d {
    return Vector3d(-0.02 * X.x() * (X.z() - 0.125), 0, 0.01 * X.x() * X.x());
  };
  const std::vector<test::DisplacementField> fields = {
      test::bump(Vector3d(0.5, 0.5, 0.25), 0.3, 0.01), bend, kink};
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const ActiveCut fine = ActiveCut::uniform(tree, 1);
    const test::CutSnapshot s = make_snapshot(fine, test_material(), fields[f], {});
    const RecoveryEstimate estimate = recovery_error_estimate(s.state());
    const BudgetedMerges all = merges_within_budget(s.state(), estimate, roots(tree), 1.0);
    ASSERT_EQ(all.kept.size(), static_cast<std::size_t>(tree.num_roots())) << "field " << f;
    const ActiveCut coarse = ActiveCut::uniform(tree, 0);
    const double merged =
        recovery_error_estimate(make_snapshot(coarse, test_material(), fields[f], {}).state())
            .recovery_error;
    ASSERT_GT(merged, estimate.recovery_error) << "field " << f;
    // The prediction is on the safe side. For smooth fields, whose error energy rises by 4 per
    // level as the prediction assumes, it may exceed the merged cut's estimate by at most 2 (a
    // prediction twice too high would hold back merges that half the budget's room could take;
    // measured: 1.13 for the bump, 1.42 for the bending). A strain jump's error lies in a band
    // one tet wide whose error energy rises by 2 per level, not 4, which puts z and c, and so
    // e = √(z c), up to 2^¾ further on the safe side (measured 2.12).
    const double spread = f == 2 ? 2.0 * std::pow(2.0, 0.75) : 2.0;
    EXPECT_GE(all.predicted_error, merged) << "field " << f;
    EXPECT_LE(all.predicted_error, spread * merged) << "field " << f;
  }
}

TEST(MergeBudget, KeepsNoMergeWhoseLocalTermWouldExceedTheBudget) {
  // A uniform strain plus a narrow bump on a uniform level-1 cut: the energy-norm estimate is
  // diluted, the local term is not. With a budget above the current local term, the merges away
  // from the bump are kept and those at it are not, and the merged cut's local term stays within
  // the budget (the prediction is on the safe side).
  TetTree tree(slab(), 2);
  const auto narrow = test::bump(Vector3d(0.5, 0.5, 0.25), 0.15, 0.001);
  const auto field = [&](const Vector3d& X) -> Vector3d {
    return Vector3d(0.01 * X.x(), 0, 0) + narrow(X);
  };
  ActiveCut cut = ActiveCut::uniform(tree, 1);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), field, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  ASSERT_GT(estimate.local_error, 2.0 * estimate.recovery_error);
  const double budget = 1.5 * estimate.local_error;
  const BudgetedMerges merges = merges_within_budget(s.state(), estimate, roots(tree), budget);
  EXPECT_GT(merges.kept.size(), 0u);
  EXPECT_LT(merges.kept.size(), static_cast<std::size_t>(tree.num_roots()));
  for (const NodeId parent : merges.kept)
    cut.coarsen(parent);
  const RecoveryEstimate merged =
      recovery_error_estimate(make_snapshot(cut, test_material(), field, {}).state());
  EXPECT_LE(merged.local_error, budget);
  // The roots at the bump stay refined.
  for (const NodeId parent : merges.kept)
    EXPECT_GT((node_centroid(tree, parent) - Vector3d(0.5, 0.5, 0.25)).norm(), 0.15)
        << "root " << parent;
}

TEST(MergeBudget, AStillRegionBesideAStrainedOneMergesOnlyAwayFromIt) {
  // A slab at rest for x ≤ 0.5 (as inside a clamp) and bent beyond, on its finest level. The
  // children of a root in the still region carry no strain at all, but a root that touches
  // x = 0.5, once merged, is one coarse tet whose corners there see the strained side's
  // recovered strain: its local term is large. Merges of roots away from x = 0.5 are free.
  TetTree tree(slab(), 1);
  const auto bend = [](const Vector3d& X) -> Vector3d {
    const double d = std::max(0.0, X.x() - 0.5);
    return Vector3d(0, 0, 0.02 * d * d);
  };
  ActiveCut cut = ActiveCut::uniform(tree, 1);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), bend, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  ASSERT_EQ(estimate.local_error, 0.0);  // the finest level
  std::vector<NodeId> still, touching;
  for (const NodeId root : roots(tree)) {
    const Matrix3x4d corners = tree.tet_positions(root);
    const double right = corners.row(0).maxCoeff();
    if (right < 0.5 - 1e-9) still.push_back(root);
    if (std::abs(right - 0.5) < 1e-9) touching.push_back(root);
  }
  ASSERT_FALSE(still.empty());
  ASSERT_FALSE(touching.empty());
  std::vector<NodeId> candidates = still;
  candidates.insert(candidates.end(), touching.begin(), touching.end());
  std::sort(candidates.begin(), candidates.end());
  const double budget = 0.002;
  const BudgetedMerges merges = merges_within_budget(s.state(), estimate, candidates, budget);
  EXPECT_EQ(merges.kept, still);
  for (const NodeId parent : merges.kept)
    cut.coarsen(parent);
  // Each root touching x = 0.5 merged as well would have taken the local term over the budget.
  for (const NodeId parent : touching) {
    ActiveCut more = cut;
    more.coarsen(parent);
    EXPECT_GT(
        recovery_error_estimate(make_snapshot(more, test_material(), bend, {}).state()).local_error,
        budget)
        << "root " << parent;
  }
}

TEST(MergeBudget, KeepsTheMergesWhosePredictedEstimateFitsTheBudget) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = ActiveCut::uniform(tree, 1);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), kink, {});
  const RecoveryEstimate estimate = recovery_error_estimate(s.state());
  const std::vector<NodeId> parents = roots(tree);
  const BudgetedMerges all = merges_within_budget(s.state(), estimate, parents, 1.0);
  ASSERT_EQ(all.kept, parents);
  ASSERT_GT(all.predicted_error, estimate.recovery_error);

  // Below the current energy-norm estimate √(zc) nothing merges (the budget is on it), also with
  // the local term taken out of the estimate.
  RecoveryEstimate energy_only = estimate;
  energy_only.local_error = 0.0;
  energy_only.element_local_error.setZero();
  energy_only.reference_displacement = 0.0;  // no local term for the merges either
  EXPECT_TRUE(merges_within_budget(s.state(), energy_only, parents, 0.9 * estimate.recovery_error)
                  .kept.empty());
  const BudgetedMerges none =
      merges_within_budget(s.state(), estimate, parents, 0.9 * estimate.recovery_error);
  EXPECT_TRUE(none.kept.empty());
  EXPECT_EQ(none.predicted_error, estimate.recovery_error);

  // In between: a proper subset within the budget, growing with it. The roots away from the kink
  // (x = 0.4) merge first: their children carry one uniform strain.
  std::size_t previous = 0;
  for (const double fraction : {0.25, 0.5, 0.75}) {
    const double budget =
        estimate.recovery_error + fraction * (all.predicted_error - estimate.recovery_error);
    const BudgetedMerges some = merges_within_budget(s.state(), estimate, parents, budget);
    EXPECT_LE(some.predicted_error, budget);
    EXPECT_GE(some.kept.size(), previous);
    EXPECT_LT(some.kept.size(), parents.size());
    EXPECT_TRUE(std::is_sorted(some.kept.begin(), some.kept.end()));
    previous = some.kept.size();
  }
  EXPECT_GT(previous, 0u);
  // The roots two cells or more from the kink, whose children and their neighbours carry one
  // uniform strain, merge at no predicted cost: within the smallest budget above, once it is
  // above the local term too (nothing merges while ℓ exceeds the budget).
  ASSERT_GT(estimate.local_error, 0.0);
  const BudgetedMerges smallest = merges_within_budget(
      s.state(), estimate, parents,
      std::max(estimate.local_error,
               estimate.recovery_error + 0.25 * (all.predicted_error - estimate.recovery_error)));
  EXPECT_TRUE(
      merges_within_budget(s.state(), estimate, parents, 0.99 * estimate.local_error).kept.empty());
  int far = 0;
  for (const NodeId root : parents)
    if (std::abs(node_centroid(tree, root).x() - 0.4) > 0.25) {
      ++far;
      EXPECT_TRUE(std::binary_search(smallest.kept.begin(), smallest.kept.end(), root))
          << "root " << root;
    }
  EXPECT_GT(far, 0);

  // Plastic materials: e = z, and the same rules hold on z.
  Material plastic = test_material();
  plastic.plasticity = Plasticity{1e4, 1e4};
  const test::CutSnapshot p = make_snapshot(cut, plastic, kink, {});
  const RecoveryEstimate plastic_estimate = recovery_error_estimate(p.state());
  ASSERT_TRUE(plastic_estimate.upper_only);
  const BudgetedMerges plastic_all =
      merges_within_budget(p.state(), plastic_estimate, parents, 1.0);
  ASSERT_EQ(plastic_all.kept, parents);
  const double plastic_budget =
      0.5 * (plastic_estimate.recovery_error + plastic_all.predicted_error);
  const BudgetedMerges plastic_some =
      merges_within_budget(p.state(), plastic_estimate, parents, plastic_budget);
  EXPECT_LE(plastic_some.predicted_error, plastic_budget);
  EXPECT_GT(plastic_some.kept.size(), 0u);
  EXPECT_LT(plastic_some.kept.size(), parents.size());

  // Without deformation (relative to an energy scale, as the driver's states are) every merge is
  // kept.
  const test::CutSnapshot rest = make_snapshot(cut, test_material(), test::no_motion, {});
  CutState at_rest_state = rest.state();
  at_rest_state.solution_energy_scale = estimate.reference_energy_sq;
  const BudgetedMerges at_rest =
      merges_within_budget(at_rest_state, recovery_error_estimate(at_rest_state), parents, 1e-6);
  EXPECT_EQ(at_rest.kept, parents);
}

}  // namespace
}  // namespace strata
