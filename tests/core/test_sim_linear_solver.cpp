#include <gtest/gtest.h>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// Final positions of a clamped column under sideways gravity, solved with the given linear solver.
VectorXd solve_column(SimulationMode mode, LinearSolverKind solver) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.2, 0.2, 1.0), {2, 2, 6});
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
  settings.linear_solver = solver;
  settings.dt = 0.01;
  settings.duration = 0.1;
  settings.load_steps = 2;
  Simulation sim(mesh, material, {base}, {}, std::nullopt, Vector3d(5, 0, -9.81), settings);
  while (!sim.finished())
    sim.advance();
  EXPECT_GT(sim.counters().newton_iterations, 0);
  EXPECT_GT(sim.counters().factorizations, 0);
  return sim.positions();
}

TEST(SimLinearSolver, ConjugateGradientsMatchCholmod) {
  for (SimulationMode mode : {SimulationMode::static_equilibrium, SimulationMode::dynamic}) {
    const VectorXd cholmod = solve_column(mode, LinearSolverKind::cholmod);
    const VectorXd cg = solve_column(mode, LinearSolverKind::cg);
    const VectorXd rest =
        flatten(box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.2, 0.2, 1.0), {2, 2, 6}).vertices);
    const double displacement = (cholmod - rest).lpNorm<Eigen::Infinity>();
    EXPECT_GT(displacement, 1e-4);
    EXPECT_LT((cholmod - cg).lpNorm<Eigen::Infinity>(), 1e-7 * displacement) << to_string(mode);
  }
}

}  // namespace
}  // namespace strata
