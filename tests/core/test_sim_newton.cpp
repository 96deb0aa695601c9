// Newton on the static problem: quadratic convergence with the exact Hessian, fewer iterations
// than with the PSD-projected Hessian alone, the shifted exact Hessian past a fold, the increment
// criterion when the residual target is out of reach, a stalled residual accepted only when small
// against the force scale, and the counters a Simulation reports.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "problem_test_utils.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/energy/elastic_term.hpp"
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/core/sim/static_solver.hpp"

namespace strata {
namespace {

Material stvk_material() {
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 5e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

/// A 1 m × 0.1 m × 0.1 m StVK cantilever clamped at x = 0 under gravity, bending by about 10 %
/// of its length at full load, with its Problem.
struct Cantilever : testing::BoxProblem {
  Cantilever()
      : BoxProblem(Vector3d(1, 0.1, 0.1), {16, 2, 2}, stvk_material(), Vector3d(0, 0, -9.81),
                   true) {}

  /// Solves load steps 1/n … 1 from rest, each from the previous solution; returns the results.
  std::vector<NewtonResult> solve(int load_steps, NewtonControls controls, VectorXd& q) const {
    StaticSolver solver(*problem, LinearSolverKind::cholmod, controls);
    q = model->rest_positions();
    std::vector<NewtonResult> results;
    for (int k = 1; k <= load_steps; ++k)
      results.push_back(solver.solve(static_cast<double>(k) / load_steps, q));
    return results;
  }

  /// Minimises the static energy at full load (elastic plus external work) from rest into `q`,
  /// with `settings` (its rest positions set here).
  NewtonResult minimize(NewtonSettings settings, VectorXd& q) const {
    EnergySum energy(embedded->stiffness_pattern());
    energy.emplace<ElasticTerm>(*embedded);
    energy.emplace<ExternalWorkTerm>(external);
    const DofReduction reduction(embedded->stiffness_pattern(), constrained);
    SpdSolver solver(LinearSolverKind::cholmod);
    settings.rest_positions = &model->rest_positions();
    q = model->rest_positions();
    return newton_minimize(energy, reduction, solver, settings, q);
  }
};

double tip_deflection(const Cantilever& c, const VectorXd& q) {
  double deflection = 0.0;
  for (Index v = 0; v < c.mesh.vertices.rows(); ++v)
    deflection = std::min(deflection, q[3 * v + 2] - c.mesh.vertices(v, 2));
  return deflection;
}

TEST(Newton, ExactHessianConvergesQuadratically) {
  const Cantilever c;
  VectorXd q;
  const std::vector<NewtonResult> results = c.solve(2, {}, q);
  EXPECT_LT(tip_deflection(c, q), -0.05);  // a geometrically nonlinear bend
  for (const NewtonResult& r : results) {
    ASSERT_TRUE(r.converged);
    EXPECT_EQ(r.criterion, NewtonCriterion::residual);
    EXPECT_EQ(r.exact_hessian_iterations, r.iterations);
    // Order of convergence from three successive residuals above round-off:
    // log(r₂/r₁) / log(r₁/r₀) ≈ 2 for Newton, 1 for a linearly converging iteration.
    const std::vector<double>& res = r.residuals;
    ASSERT_GE(res.size(), 4u);
    const size_t n = res.size();
    const double order = std::log(res[n - 2] / res[n - 3]) / std::log(res[n - 3] / res[n - 4]);
    std::ostringstream sequence;
    for (double value : res)
      sequence << ' ' << value;
    EXPECT_GT(order, 1.6) << "residuals" << sequence.str();
  }
}

TEST(Newton, ExactHessianNeedsFewerIterationsThanProjected) {
  const Cantilever c;
  VectorXd q_exact, q_projected;
  NewtonControls projected;
  projected.exact_hessian = false;
  int exact_iterations = 0, projected_iterations = 0;
  for (const NewtonResult& r : c.solve(2, {}, q_exact))
    exact_iterations += r.iterations;
  for (const NewtonResult& r : c.solve(2, projected, q_projected)) {
    ASSERT_TRUE(r.converged);
    EXPECT_EQ(r.projected_hessian_iterations, r.iterations);
    projected_iterations += r.iterations;
  }
  std::printf("Newton iterations over 2 load steps: exact where PD %d, projected %d\n",
              exact_iterations, projected_iterations);
  EXPECT_LT(exact_iterations, projected_iterations);
  // Both minimise the same energy: the same equilibrium.
  EXPECT_LE((q_exact - q_projected).lpNorm<Eigen::Infinity>(),
            1e-8 * std::abs(tip_deflection(c, q_exact)));
}

/// A 0.2 m neo-Hookean cube (6 × 6 × 6 cells) clamped at its base, its top face moved down by
/// 0.14 m (to 30 % of its height) in 30 static load steps, with Newton's Hessian as given; the
/// most Newton iterations a load step took in `most_iterations`.
std::unique_ptr<Simulation> compressed_cube(bool exact_hessian, int max_iterations,
                                            long* most_iterations = nullptr) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Constant(0.2), {6, 6, 6});
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  DirichletSpec base;
  base.name = "fixed[0]";
  base.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitZ(), 0.0};
  DirichletSpec top;
  top.name = "displacement[0]";
  top.region = PlaneRegion{Vector3d(0, 0, 0.2), Vector3d::UnitZ(), 0.0};
  top.kind = DirichletKind::displacement;
  top.displacement = Vector3d(0, 0, -0.14);
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 30;
  settings.newton.exact_hessian = exact_hessian;
  settings.newton.max_iterations = max_iterations;
  auto sim = std::make_unique<Simulation>(
      mesh, ProblemSpec{.material = material, .dirichlet = {base, top}}, settings);
  long most = 0;
  while (!sim->finished()) {
    const long before = sim->counters().newton_iterations;
    sim->advance();
    most = std::max(most, sim->counters().newton_iterations - before);
  }
  if (most_iterations != nullptr) *most_iterations = most;
  return sim;
}

TEST(Newton, ShiftedExactHessianCarriesACompressedCubePastItsFold) {
  // Past about half its height the cube's sides fold: the exact Hessian turns indefinite for
  // some iterations of the load steps after that. Shifted just enough to be positive definite, it
  // keeps Newton within the default 50 iterations of every step. (With the per-element projection
  // wherever the exact Hessian was not positive definite, Newton stopped at the last load step
  // after 50 iterations.)
  std::unique_ptr<Simulation> sim;
  long most_iterations = 0;
  ASSERT_NO_THROW(sim = compressed_cube(true, 0, &most_iterations));
  // No step reached the limit (where a residual within the stall bound would also be accepted).
  EXPECT_LT(most_iterations, 50);
  const SimulationCounters counters = sim->counters();
  EXPECT_GT(counters.shifted_hessian_iterations, 0);
  EXPECT_LE(counters.projected_hessian_iterations, 5);
  EXPECT_LE(counters.newton_iterations, 10 * 30);

  // Independently of Newton's own residual: the free vertices' elastic forces balance (no load
  // acts on them) to within the bound a stalled step may keep, 1e-5 of the forces at work.
  const ElasticModel& model = sim->model();
  const VectorXd x = sim->positions();
  VectorXd f;
  model.forces(x, f);
  const TetMesh& mesh = sim->mesh();
  const auto constrained = [&](Index v) {
    return mesh.vertices(v, 2) < 1e-9 || mesh.vertices(v, 2) > 0.2 - 1e-9;
  };
  double free_sq = 0.0;
  std::vector<Index> free_dofs;
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    if (constrained(v)) continue;
    free_sq += f.segment<3>(3 * v).squaredNorm();
    for (int k = 0; k < 3; ++k)
      free_dofs.push_back(3 * v + k);
  }
  EXPECT_LE(std::sqrt(free_sq), 1e-5 * f.norm());

  // …and the state is a stable equilibrium, not a saddle: the exact Hessian over the free DOFs
  // has a Cholesky factorisation (Eigen's LDLᵀ with every pivot positive).
  SparseMatrixd K;
  model.stiffness(x, K, false);
  std::vector<int> index(x.size(), -1);
  for (std::size_t i = 0; i < free_dofs.size(); ++i)
    index[free_dofs[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (Index c = 0; c < K.outerSize(); ++c)
    for (SparseMatrixd::InnerIterator it(K, c); it; ++it)
      if (index[it.row()] >= 0 && index[it.col()] >= 0)
        entries.emplace_back(index[it.row()], index[it.col()], it.value());
  const Index n = static_cast<Index>(free_dofs.size());
  SparseMatrixd K_free(n, n);
  K_free.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<SparseMatrixd> ldlt(K_free);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  EXPECT_GT(ldlt.vectorD().minCoeff(), 0.0);

  // The projection alone, given 3,000 iterations a step, ends on a state of higher energy.
  const std::unique_ptr<Simulation> projected = compressed_cube(false, 3000);
  EXPECT_LT(sim->elastic_energy(), projected->elastic_energy());
}

TEST(Newton, UnreachableResidualConvergesOnTheIncrement) {
  const Cantilever c;
  VectorXd q_reference;
  c.solve(1, {}, q_reference);
  // The static energy at full load, minimised with a residual target of zero: only the increment
  // (or a stall at round-off) can end the solve.
  NewtonSettings settings;
  settings.tolerance = 0.0;
  settings.residual_floor = 0.0;
  VectorXd q;
  const NewtonResult r = c.minimize(settings, q);
  ASSERT_TRUE(r.converged) << "residual " << r.residual;
  EXPECT_NE(r.criterion, NewtonCriterion::residual);
  EXPECT_LE(r.iterations, 15);
  EXPECT_LE((q - q_reference).lpNorm<Eigen::Infinity>(),
            1e-8 * std::abs(tip_deflection(c, q_reference)));
}

TEST(Newton, AKeptWorkspaceGivesTheSameSolvesAsFreshMatrices) {
  // Two load steps minimised with one workspace kept between the calls, against the same calls
  // with matrices of their own: the same iterates to the bit. A workspace left by another energy
  // is started afresh: here its matrices have this energy's sizes and column starts but other
  // rows, which, reused as they are, would put the Hessians in the wrong entries.
  const Cantilever c;
  EnergySum energy(c.embedded->stiffness_pattern());
  energy.emplace<ElasticTerm>(*c.embedded);
  ExternalWorkTerm& work = energy.emplace<ExternalWorkTerm>(c.external);
  const DofReduction reduction(c.embedded->stiffness_pattern(), c.constrained);
  NewtonSettings settings;
  settings.force_scale = c.external.norm();
  settings.rest_positions = &c.model->rest_positions();

  // Matrices of the same sizes and column lengths as this energy's, with other rows in each
  // column: reused as they are, the Hessians would land in the wrong entries.
  const auto shuffled = [](const SparseMatrixd& pattern) {
    SparseMatrixd m = pattern;
    for (Index j = 0; j < m.outerSize(); ++j) {
      const int length = m.outerIndexPtr()[j + 1] - m.outerIndexPtr()[j];
      for (int k = 0; k < length; ++k)
        m.innerIndexPtr()[m.outerIndexPtr()[j] + k] = k;  // rows 0 … length − 1
    }
    return m;
  };
  SparseMatrixd reduced_pattern;
  reduction.restrict_matrix(c.embedded->stiffness_pattern(), reduced_pattern);
  const EnergySum other(c.embedded->stiffness_pattern());
  NewtonWorkspace workspace;
  workspace.hessian = shuffled(c.embedded->stiffness_pattern());
  workspace.reduced_hessian = shuffled(reduced_pattern);
  workspace.energy = &other;
  workspace.pattern = &c.embedded->stiffness_pattern();
  workspace.reduction = &reduction;

  SpdSolver kept_solver(LinearSolverKind::cholmod), fresh_solver(LinearSolverKind::cholmod);
  VectorXd kept = c.model->rest_positions(), fresh = kept;
  for (const double load : {0.5, 1.0}) {
    work.set_load_factor(load);
    const NewtonResult with_workspace =
        newton_minimize(energy, reduction, kept_solver, settings, kept, &workspace);
    const NewtonResult without = newton_minimize(energy, reduction, fresh_solver, settings, fresh);
    ASSERT_TRUE(with_workspace.converged);
    EXPECT_EQ(with_workspace.residuals, without.residuals) << "load " << load;
    EXPECT_EQ(kept, fresh) << "load " << load;
    EXPECT_EQ(workspace.energy, &energy);
    EXPECT_EQ(workspace.pattern, &energy.pattern());
    EXPECT_EQ(workspace.reduced_hessian.rows(), reduction.num_free());
  }
}

/// E = 0 with a gradient k (q − a) + δ (q − a)/‖q − a‖ of norm k‖q − a‖ + δ ≥ δ: Newton reaches
/// q ≈ a, where no step can bring ‖g‖ below δ (a residual stalled at δ) and E cannot tell steps
/// apart.
class StalledGradientTerm final : public EnergyTerm {
 public:
  StalledGradientTerm(VectorXd a, double k, double delta)
      : m_a(std::move(a)), m_k(k), m_delta(delta) {}
  std::string_view name() const override { return "stalled"; }
  double value(ConstRef<VectorXd>) const override { return 0.0; }
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override {
    const VectorXd d = q - m_a;
    const double r = d.norm();
    gradient += m_k * d;
    if (r > 0.0)
      gradient += m_delta / r * d;
    else
      gradient[0] += m_delta;  // at a itself: any direction, still of norm δ
  }
  void add_hessian(ConstRef<VectorXd>, SparseMatrixd& hessian, bool) const override {
    add_diagonal(VectorXd::Constant(m_a.size(), m_k), hessian);
  }

 private:
  VectorXd m_a;
  double m_k, m_delta;
};

TEST(Newton, ASolveStoppedByItsIterationLimitSaysSo) {
  const Cantilever c;
  NewtonSettings settings;
  settings.max_iterations = 1;  // the bending cantilever needs several
  VectorXd q;
  const NewtonResult r = c.minimize(settings, q);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.failure, NewtonFailure::iteration_limit);
  EXPECT_EQ(describe(r.failure), "the iteration limit");
  settings.max_iterations = 50;
  const NewtonResult full = c.minimize(settings, q);
  EXPECT_TRUE(full.converged);
  EXPECT_GT(full.iterations, 1);
  EXPECT_EQ(full.failure, NewtonFailure::none);
}

TEST(Newton, OutOfIterationsWithAResidualARoundOffStallWouldAcceptIsConverged) {
  // The cantilever's static solve with an unreachable residual target, cut off after three
  // iterations: against a force scale its residual is 1e-5 of by then it has stalled (converged,
  // as a stall); against one ten thousand times smaller it has not (the iteration limit).
  const Cantilever c;
  NewtonSettings settings;
  settings.tolerance = 0.0;
  settings.residual_floor = 0.0;
  settings.increment_tolerance = 0.0;
  settings.step_tolerance = 0.0;
  settings.max_iterations = 3;
  VectorXd q;
  const NewtonResult probe = c.minimize(settings, q);
  ASSERT_FALSE(probe.converged);
  ASSERT_EQ(probe.failure, NewtonFailure::iteration_limit);
  ASSERT_GT(probe.residual, 0.0);
  for (const double factor : {2.0, 2e-4}) {
    settings.force_scale = factor * probe.residual / settings.stall_residual_tolerance;
    const NewtonResult r = c.minimize(settings, q);
    EXPECT_EQ(r.iterations, 3);
    EXPECT_DOUBLE_EQ(r.residual, probe.residual);
    if (factor > 1.0) {
      EXPECT_TRUE(r.converged);
      EXPECT_EQ(r.criterion, NewtonCriterion::stall);
      EXPECT_EQ(r.failure, NewtonFailure::none);
    } else {
      EXPECT_FALSE(r.converged);
      EXPECT_EQ(r.failure, NewtonFailure::iteration_limit);
    }
  }
}

TEST(Newton, StalledResidualIsConvergedOnlyWhenSmallAgainstTheForceScale) {
  const Cantilever c;
  const double delta = 1e-6;  // the stalled residual [N]
  const VectorXd& rest = c.model->rest_positions();
  const VectorXd a = rest + VectorXd::Constant(rest.size(), 0.1);
  const DofReduction reduction(c.embedded->stiffness_pattern(),
                               std::vector<char>(static_cast<size_t>(rest.size()), 0));
  for (const double force_scale : {1.0, 0.01}) {
    EnergySum energy(c.embedded->stiffness_pattern());
    energy.emplace<StalledGradientTerm>(a, 1.0, delta);
    SpdSolver solver(LinearSolverKind::cholmod);
    NewtonSettings settings;
    settings.tolerance = 0.0;  // the residual criterion cannot be met
    settings.residual_floor = 0.0;
    settings.force_scale = force_scale;
    settings.energy_scale = 1.0;
    settings.rest_positions = &rest;
    VectorXd q = rest;
    const NewtonResult r = newton_minimize(energy, reduction, solver, settings, q);
    // The last corrections (δ/k spread over the DOFs) stay far above round-off of the 0.1 m
    // displacement, so only the residual's size against the force scale can make this converged.
    EXPECT_NEAR(r.residual, delta, 1e-3 * delta) << "force scale " << force_scale;
    EXPECT_LT(r.iterations, settings.max_iterations);
    if (delta <= settings.stall_residual_tolerance * force_scale) {
      EXPECT_TRUE(r.converged) << "force scale " << force_scale;
      EXPECT_EQ(r.criterion, NewtonCriterion::stall);
      EXPECT_EQ(r.failure, NewtonFailure::none);
    } else {
      EXPECT_FALSE(r.converged) << "force scale " << force_scale;
      EXPECT_EQ(r.failure, NewtonFailure::no_descent);
    }
  }
}

TEST(Newton, SimulationCountsHessianKindsAndCriteria) {
  const Cantilever c;
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 3;
  DirichletSpec clamp;
  clamp.name = "fixed[0]";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  Simulation sim(c.mesh,
                 {.material = c.material, .dirichlet = {clamp}, .gravity = Vector3d(0, 0, -9.81)},
                 settings);
  while (!sim.finished())
    sim.advance();
  const SimulationCounters counters = sim.counters();
  EXPECT_GT(counters.newton_iterations, 0);
  EXPECT_EQ(counters.exact_hessian_iterations + counters.shifted_hessian_iterations +
                counters.projected_hessian_iterations,
            counters.newton_iterations);
  EXPECT_EQ(counters.stalled_steps, 0);
  EXPECT_LE(counters.max_residual_ratio, 1.0);
  EXPECT_LE(counters.newton_iterations, 5 * settings.load_steps);
}

}  // namespace
}  // namespace strata
