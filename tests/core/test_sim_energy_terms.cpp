// Energy terms of the Problem: finite-difference checks of every term's gradient (against its
// value) and Hessian (against its gradient), exact and PSD-projected, and the EnergySum as the
// sum of its terms.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>
#include <string>

#include "fem_test_utils.hpp"
#include "problem_test_utils.hpp"
#include "strata/core/sim/energy/elastic_term.hpp"
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/energy/ground_penalty_term.hpp"
#include "strata/core/sim/energy/inertia_term.hpp"
#include "strata/core/sim/energy/rayleigh_damping_term.hpp"

namespace strata {
namespace {

Material term_material(MaterialModel kind) {
  Material material;
  material.model = kind;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  return material;
}

/// A 2×1×1-cell box (12 tets) with its model, masses, random loads and a deformed state.
struct TermFixture : testing::BoxProblem {
  VectorXd forces, state, velocity;

  explicit TermFixture(MaterialModel kind)
      : BoxProblem(Vector3d(0.2, 0.1, 0.1), {2, 1, 1}, term_material(kind), Vector3d::Zero(),
                   false) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    state = model->rest_positions();
    forces.resize(state.size());
    velocity.resize(state.size());
    for (Index i = 0; i < state.size(); ++i) {
      state[i] += 0.01 * uniform(rng);
      forces[i] = uniform(rng);
      velocity[i] = uniform(rng);
    }
  }
};

/// Central differences of value and gradient at q along random directions, relative errors.
void expect_derivatives_match(const EnergyTerm& term, const SparseMatrixd& pattern,
                              const VectorXd& q, bool project_psd, double tolerance) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VectorXd gradient = VectorXd::Zero(q.size());
  term.add_gradient(q, gradient);
  SparseMatrixd H = pattern;
  std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  term.add_hessian(q, H, project_psd);
  for (int trial = 0; trial < 3; ++trial) {
    VectorXd direction(q.size());
    for (Index i = 0; i < q.size(); ++i)
      direction[i] = uniform(rng);
    const double h = 1e-6;
    const double fd_slope =
        (term.value(q + h * direction) - term.value(q - h * direction)) / (2 * h);
    const double slope = gradient.dot(direction);
    EXPECT_NEAR(fd_slope, slope, tolerance * std::max(1.0, std::abs(slope))) << term.name();
    if (project_psd) continue;  // the projected Hessian is not the derivative of the gradient
    VectorXd g_plus = VectorXd::Zero(q.size()), g_minus = VectorXd::Zero(q.size());
    term.add_gradient(q + h * direction, g_plus);
    term.add_gradient(q - h * direction, g_minus);
    const VectorXd fd_hessian = (g_plus - g_minus) / (2 * h);
    const VectorXd hessian = H * direction;
    EXPECT_LE((fd_hessian - hessian).norm(), tolerance * std::max(1.0, hessian.norm()))
        << term.name();
  }
  if (project_psd) {
    // PSD: vᵀ H v ≥ 0 for every tested direction.
    for (int trial = 0; trial < 5; ++trial) {
      VectorXd direction(q.size());
      for (Index i = 0; i < q.size(); ++i)
        direction[i] = uniform(rng);
      EXPECT_GE(direction.dot(H * direction), -1e-9 * H.norm()) << term.name();
    }
  }
}

TEST(EnergyTerms, ElasticDerivativesMatchFiniteDifferences) {
  for (MaterialModel kind : testing::kAllModels) {
    TermFixture f(kind);
    ElasticTerm term(*f.embedded);
    expect_derivatives_match(term, f.embedded->stiffness_pattern(), f.state, false, 1e-5);
    expect_derivatives_match(term, f.embedded->stiffness_pattern(), f.state, true, 1e-5);
  }
}

TEST(EnergyTerms, InertiaDerivativesMatchFiniteDifferences) {
  TermFixture f(MaterialModel::stvk);
  InertiaTerm term(f.mass);
  const double h = 1e-2;
  term.set_step(f.model->rest_positions() + h * f.velocity, h);
  expect_derivatives_match(term, f.embedded->stiffness_pattern(), f.state, false, 1e-6);
  // At q = q̃ the term and its gradient vanish.
  VectorXd gradient = VectorXd::Zero(f.state.size());
  const VectorXd predicted = f.model->rest_positions() + h * f.velocity;
  term.add_gradient(predicted, gradient);
  EXPECT_EQ(term.value(predicted), 0.0);
  EXPECT_EQ(gradient.norm(), 0.0);
}

TEST(EnergyTerms, RayleighDampingGradientIsTheDampingForce) {
  TermFixture f(MaterialModel::neohookean);
  const double alpha = 0.7, beta = 0.02, h = 1e-2;
  RayleighDampingTerm term(*f.embedded, f.mass, alpha, beta);
  term.set_step(f.state, h);
  const VectorXd q = f.state + h * f.velocity;
  expect_derivatives_match(term, f.embedded->stiffness_pattern(), q, false, 1e-6);
  // ∂E/∂q = (α M + β Kₙ) v with v = (q − qₙ)/h: compare with an independent product.
  SparseMatrixd K;
  f.embedded->stiffness(f.state, K, true);
  const VectorXd expected = alpha * f.mass.cwiseProduct(f.velocity) + beta * (K * f.velocity);
  VectorXd gradient = VectorXd::Zero(q.size());
  term.add_gradient(q, gradient);
  EXPECT_LE((gradient - expected).norm(), 1e-10 * expected.norm());
}

TEST(EnergyTerms, ExternalWorkIsLinearInTheLoadFactor) {
  TermFixture f(MaterialModel::stvk);
  ExternalWorkTerm term(f.forces);
  term.set_load_factor(0.3);
  EXPECT_NEAR(term.value(f.state), -0.3 * f.forces.dot(f.state), 1e-14);
  expect_derivatives_match(term, f.embedded->stiffness_pattern(), f.state, false, 1e-7);
}

TEST(EnergyTerms, GroundPenaltyDerivativesMatchFiniteDifferences) {
  TermFixture f(MaterialModel::stvk);
  GroundPlane ground;
  ground.point = Vector3d(0, 0, 0.05);  // cuts through the box: half the vertices penetrate
  ground.normal = Vector3d(0.1, 0.2, 1.0);
  GroundPenaltyTerm term(ground, 1e4);
  EXPECT_GT(term.value(f.state), 0.0);
  expect_derivatives_match(term, f.embedded->stiffness_pattern(), f.state, false, 1e-6);
}

TEST(EnergyTerms, SumIsTheSumOfItsTerms) {
  TermFixture f(MaterialModel::corotated);
  EnergySum sum(f.embedded->stiffness_pattern());
  const double h = 5e-3;
  auto& inertia = sum.emplace<InertiaTerm>(f.mass);
  inertia.set_step(f.model->rest_positions(), h);
  sum.emplace<ElasticTerm>(*f.embedded);
  sum.emplace<ExternalWorkTerm>(f.forces);
  ASSERT_EQ(sum.terms().size(), 3u);
  double value = 0.0;
  VectorXd gradient = VectorXd::Zero(f.state.size());
  SparseMatrixd H = f.embedded->stiffness_pattern();
  std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  for (const auto& term : sum.terms()) {
    value += term->value(f.state);
    term->add_gradient(f.state, gradient);
    term->add_hessian(f.state, H, false);
  }
  EXPECT_NEAR(sum.value(f.state), value, 1e-12 * std::abs(value));
  VectorXd sum_gradient;
  sum.gradient(f.state, sum_gradient);
  EXPECT_LE((sum_gradient - gradient).norm(), 1e-12 * gradient.norm());
  SparseMatrixd sum_hessian;
  sum.hessian(f.state, sum_hessian, false);
  EXPECT_LE((sum_hessian - H).norm(), 1e-12 * H.norm());
}

TEST(EnergyTerms, SumHessianIsBitForBitAZeroFillAndTheTermsAddedInOrder) {
  // The sum lets one of its first two terms write the Hessian (ElasticTerm::set_hessian) instead
  // of a zero fill and an add; the values must be exactly those of the plain order.
  TermFixture f(MaterialModel::neohookean);
  const double h = 5e-3;
  RayleighDampingTerm damping(*f.embedded, f.mass, 2.0, 1e-3);
  damping.set_step(f.model->rest_positions(), h);
  for (const std::string order : {"IEX", "EIX", "IXE"}) {
    EnergySum sum(f.embedded->stiffness_pattern());
    for (const char term : order) {
      if (term == 'I') sum.emplace<InertiaTerm>(f.mass).set_step(f.model->rest_positions(), h);
      if (term == 'E') sum.emplace<ElasticTerm>(*f.embedded);
      if (term == 'X') sum.emplace<ExternalWorkTerm>(f.forces);
    }
    SparseMatrixd plain = f.embedded->stiffness_pattern();
    std::fill(plain.valuePtr(), plain.valuePtr() + plain.nonZeros(), 0.0);
    for (const auto& term : sum.terms())
      term->add_hessian(f.state, plain, false);
    SparseMatrixd summed;
    sum.hessian(f.state, summed, false);
    ASSERT_EQ(summed.nonZeros(), plain.nonZeros()) << order;
    Index different = 0;
    for (Index k = 0; k < plain.nonZeros(); ++k)
      different += summed.valuePtr()[k] != plain.valuePtr()[k];
    EXPECT_EQ(different, 0) << order;
    // A second evaluation overwrites rather than adds.
    sum.hessian(f.state, summed, false);
    EXPECT_TRUE(
        std::equal(plain.valuePtr(), plain.valuePtr() + plain.nonZeros(), summed.valuePtr()))
        << order;
  }
  // ElasticTerm::set_hessian writes what add_hessian adds to zeros.
  ElasticTerm elastic(*f.embedded);
  SparseMatrixd added = f.embedded->stiffness_pattern();
  std::fill(added.valuePtr(), added.valuePtr() + added.nonZeros(), 0.0);
  elastic.add_hessian(f.state, added, true);
  SparseMatrixd set = f.embedded->stiffness_pattern();
  std::fill(set.valuePtr(), set.valuePtr() + set.nonZeros(), 7.0);  // overwritten
  ASSERT_TRUE(elastic.set_hessian(f.state, set, true));
  EXPECT_TRUE(std::equal(added.valuePtr(), added.valuePtr() + added.nonZeros(), set.valuePtr()));
  EXPECT_FALSE(damping.set_hessian(f.state, set, false));  // a term that only adds
}

TEST(EnergyTerms, DiagonalPositionsAddWhatAddDiagonalAddsAndFollowThePattern) {
  // The cached positions give the values of the searching add_diagonal, bit for bit, on the
  // pattern they were found in and again on another pattern handed to the same object.
  TermFixture f(MaterialModel::neohookean);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(0.5, 2.0);
  DiagonalPositions positions;
  for (int round = 0; round < 2; ++round) {
    // Round 0: the model's pattern; round 1: a tridiagonal pattern of another size.
    SparseMatrixd pattern = f.embedded->stiffness_pattern();
    if (round == 1) {
      const Index n = pattern.rows() + 5;
      std::vector<Eigen::Triplet<double>> triplets;
      for (Index i = 0; i < n; ++i)
        for (Index j = std::max<Index>(0, i - 1); j <= std::min(n - 1, i + 1); ++j)
          triplets.emplace_back(i, j, 1.0);
      pattern.resize(n, n);
      pattern.setFromTriplets(triplets.begin(), triplets.end());
    }
    for (Index k = 0; k < pattern.nonZeros(); ++k)
      pattern.valuePtr()[k] = uniform(rng);
    VectorXd weights(pattern.rows());
    for (Index i = 0; i < weights.size(); ++i)
      weights[i] = uniform(rng);
    const double scale = 1.0 / 3.0;
    SparseMatrixd expected = pattern;
    add_diagonal(scale * weights, expected);
    for (int use = 0; use < 2; ++use) {  // the second use reads the cached positions
      SparseMatrixd added = pattern;
      positions.add(scale, weights, added);
      EXPECT_TRUE(std::equal(expected.valuePtr(), expected.valuePtr() + expected.nonZeros(),
                             added.valuePtr()))
          << "round " << round << ", use " << use;
    }
  }
  // The same matrix object rewritten with another pattern of the same size and non-zero count
  // (upper bidiagonal, then the diagonal with a full first column: the diagonal entries of
  // columns 1–6 move from 2j to 6 + j): the positions follow.
  const auto pattern_of = [](Index n, bool bidiagonal) {
    std::vector<Eigen::Triplet<double>> triplets;
    for (Index i = 0; i < n; ++i) {
      triplets.emplace_back(i, i, 1.0 + i);
      if (bidiagonal && i + 1 < n) triplets.emplace_back(i, i + 1, 0.5);
      if (!bidiagonal && i > 0) triplets.emplace_back(i, 0, 0.5);
    }
    SparseMatrixd m(n, n);
    m.setFromTriplets(triplets.begin(), triplets.end());
    return m;
  };
  const SparseMatrixd upper = pattern_of(7, true), lower = pattern_of(7, false);
  ASSERT_EQ(upper.nonZeros(), lower.nonZeros());
  SparseMatrixd reused = upper;
  DiagonalPositions follows;
  const VectorXd ones = VectorXd::Ones(7);
  follows.add(1.0, ones, reused);
  std::copy(lower.outerIndexPtr(), lower.outerIndexPtr() + 8, reused.outerIndexPtr());
  std::copy(lower.innerIndexPtr(), lower.innerIndexPtr() + lower.nonZeros(),
            reused.innerIndexPtr());
  std::copy(lower.valuePtr(), lower.valuePtr() + lower.nonZeros(), reused.valuePtr());
  follows.add(1.0, ones, reused);
  SparseMatrixd expected_lower = lower;
  add_diagonal(ones, expected_lower);
  EXPECT_TRUE(std::equal(expected_lower.valuePtr(),
                         expected_lower.valuePtr() + expected_lower.nonZeros(), reused.valuePtr()));
  // A pattern without a full diagonal is refused, and the positions cached before stay usable.
  SparseMatrixd off_diagonal(2, 2);
  off_diagonal.insert(0, 1) = 1.0;
  off_diagonal.insert(1, 0) = 1.0;
  off_diagonal.makeCompressed();
  DiagonalPositions fresh;
  EXPECT_ANY_THROW(fresh.add(1.0, VectorXd::Ones(2), off_diagonal));
  EXPECT_ANY_THROW(follows.add(1.0, VectorXd::Ones(2), off_diagonal));
  SparseMatrixd again = lower;
  follows.add(1.0, ones, again);
  EXPECT_TRUE(std::equal(expected_lower.valuePtr(),
                         expected_lower.valuePtr() + expected_lower.nonZeros(), again.valuePtr()));
}

}  // namespace
}  // namespace strata
