#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <array>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// A clamped column under sideways gravity, solved with the given linear solver.
struct ColumnRun {
  VectorXd displacement;  ///< final positions − rest
  SimulationCounters counters;
};

ColumnRun solve_column(SimulationMode mode, LinearSolverKind solver,
                       const std::array<int, 3>& cells = {2, 2, 6}) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.2, 0.2, 1.0), cells);
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 5e5;
  material.stiffness_damping = 1e-3;
  DirichletSpec base;
  base.name = "fixed[0]";
  base.region = BoxRegion{Vector3d(-1, -1, 0), Vector3d(1, 1, 0)};
  SolverSettings settings;
  settings.mode = mode;
  settings.integrator = Integrator::implicit_euler;
  settings.newton.linear_solver = solver;
  settings.dt = 0.01;
  settings.duration = 0.1;
  settings.load_steps = 2;
  Simulation sim(mesh,
                 {.material = material, .dirichlet = {base}, .gravity = Vector3d(5, 0, -9.81)},
                 settings);
  while (!sim.finished())
    sim.advance();
  EXPECT_GT(sim.counters().newton_iterations, 0);
  EXPECT_GT(sim.counters().factorizations, 0);
  return {sim.positions() - flatten(mesh.vertices), sim.counters()};
}

TEST(SimLinearSolver, ConjugateGradientsMatchCholmod) {
  for (SimulationMode mode : {SimulationMode::static_equilibrium, SimulationMode::dynamic}) {
    const VectorXd cholmod = solve_column(mode, LinearSolverKind::cholmod).displacement;
    const VectorXd cg = solve_column(mode, LinearSolverKind::cg).displacement;
    const double displacement = cholmod.lpNorm<Eigen::Infinity>();
    EXPECT_GT(displacement, 1e-4);
    EXPECT_LT((cholmod - cg).lpNorm<Eigen::Infinity>(), 1e-7 * displacement) << to_string(mode);
  }
}

TEST(SimLinearSolver, AlgebraicMultigridMatchesCholmod) {
  // A finer column (1,875 DOFs): large enough for hypre to coarsen.
  for (SimulationMode mode : {SimulationMode::static_equilibrium, SimulationMode::dynamic}) {
    const ColumnRun direct = solve_column(mode, LinearSolverKind::cholmod, {4, 4, 20});
    const ColumnRun amg = solve_column(mode, LinearSolverKind::amg, {4, 4, 20});
    EXPECT_EQ(amg.counters.linear_solver, LinearSolverKind::amg) << to_string(mode);
    EXPECT_EQ(amg.counters.multigrid_direct_fallbacks, 0) << to_string(mode);
    EXPECT_GE(amg.counters.multigrid_setups, 1) << to_string(mode);
    const double displacement = direct.displacement.lpNorm<Eigen::Infinity>();
    EXPECT_GT(displacement, 1e-3);
    EXPECT_LT((direct.displacement - amg.displacement).lpNorm<Eigen::Infinity>(),
              1e-7 * displacement)
        << to_string(mode);
  }
}

/// The stiffness of a box clamped at z = 0, at a state stretched along z by `strain`, plus
/// `shift` · I, free DOFs only.
SparseMatrixd clamped_stiffness(double shift, double strain = 0.0) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.3, 0.2, 1.0), {3, 2, 8});
  Material material;
  material.model = MaterialModel::stvk;
  const ElasticModel model(mesh.vertices, mesh.tets, material);
  SparseMatrixd K;
  VectorXd x = model.rest_positions();
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    x[3 * v + 2] *= 1.0 + strain;
  model.stiffness(x, K, false);
  std::vector<char> constrained(model.num_dofs(), 0);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    if (mesh.vertices(v, 2) == 0.0)
      constrained[3 * v] = constrained[3 * v + 1] = constrained[3 * v + 2] = 1;
  const DofReduction reduction(K, constrained);
  SparseMatrixd reduced;
  reduction.restrict_matrix(K, reduced);
  for (Index i = 0; i < reduced.rows(); ++i)
    reduced.coeffRef(i, i) += shift;
  return reduced;
}

TEST(SimLinearSolver, PreviousFactorAnswersNearbySystemsExactly) {
  SpdSolver solver(LinearSolverKind::cholmod);
  const SparseMatrixd A0 = clamped_stiffness(0.0);
  VectorXd b = VectorXd::LinSpaced(A0.rows(), -1.0, 2.0);
  VectorXd x;
  ASSERT_TRUE(solver.solve(A0, b, x));
  EXPECT_EQ(solver.factorizations(), 1);
  // The stiffness of a nearby state (0.5 % stretch), as in a Newton sequence: answered by CG on
  // the first factor.
  const SparseMatrixd A1 = clamped_stiffness(0.0, 0.005);
  ASSERT_TRUE(solver.solve(A1, b, x));
  EXPECT_EQ(solver.factorizations(), 1);
  EXPECT_EQ(solver.reused_factor_solves(), 1);
  // Independent direct solve of the same system.
  Eigen::SimplicialLDLT<SparseMatrixd> direct(A1);
  const VectorXd expected = direct.solve(b);
  EXPECT_LE((x - expected).norm(), 1e-8 * expected.norm());
  EXPECT_LE((A1.selfadjointView<Eigen::Lower>() * x - b).norm(), 1e-9 * b.norm());
}

TEST(SimLinearSolver, IndefiniteMatrixIsRefusedNotSolvedWrongly) {
  SpdSolver solver(LinearSolverKind::cholmod);
  const SparseMatrixd A0 = clamped_stiffness(0.0);
  const VectorXd b = VectorXd::Ones(A0.rows());
  VectorXd x;
  ASSERT_TRUE(solver.solve(A0, b, x));
  // Shifting the spectrum below zero: neither the previous factor nor a new one may answer.
  const SparseMatrixd indefinite = clamped_stiffness(-0.5 * A0.diagonal().maxCoeff());
  EXPECT_FALSE(solver.solve(indefinite, b, x));
  // The solver recovers on an SPD matrix afterwards.
  EXPECT_TRUE(solver.solve(A0, b, x));
  Eigen::SimplicialLDLT<SparseMatrixd> direct(A0);
  EXPECT_LE((x - direct.solve(b)).norm(), 1e-8 * x.norm());
}

}  // namespace
}  // namespace strata
