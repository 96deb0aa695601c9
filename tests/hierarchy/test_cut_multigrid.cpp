// Multigrid over the refinement tree's levels (cut_levels.hpp, core/sim/multigrid.hpp): the
// transfers interpolate exactly, and multigrid-preconditioned CG reaches the direct (CHOLMOD)
// solution of clamped stiffness systems on full, uniform and adaptive cuts with hanging vertices,
// at ν = 0.3 and 0.49, with iteration counts that stay bounded as the box is refined.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/cut_levels.hpp"

namespace strata {
namespace {

TetMesh beam() {
  return box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 0.5, 0.5), {4, 1, 1});
}

/// The cut next to the clamp (x < 0.6) at `fine`, the rest at `coarse`, unbalanced when the
/// levels differ by more than one (chains of hanging vertices).
ActiveCut graded_cut(TetTree& tree, int coarse, int fine) {
  ActiveCut cut = ActiveCut::uniform(tree, coarse);
  for (int level = coarse; level < fine; ++level)
    for (const NodeId n : cut.sorted_nodes())
      if (tree.level(n) == level && tree.tet_positions(n).row(0).minCoeff() < 0.6) cut.refine(n);
  return cut;
}

Material material(double poisson_ratio) {
  Material m;
  m.model = MaterialModel::stvk;
  m.youngs_modulus = 1e6;
  m.poisson_ratio = poisson_ratio;
  m.density = 1000.0;
  return m;
}

/// K u = f on a cut, clamped at x = 0, f a smooth body load, reduced to the free DOFs; with the
/// cut's nested spaces.
struct ClampedSystem {
  SparseMatrixd A;
  VectorXd b;
  NestedSpaces spaces;
  std::vector<Index> free_dofs;
  Index hanging = 0;
};

ClampedSystem clamped_system(const ActiveCut& cut, double poisson_ratio) {
  const ConstrainedCut c = flatten_cut(cut);
  const ElasticModel model(c.flat.mesh.vertices, c.flat.mesh.tets, material(poisson_ratio));
  const EmbeddedElasticModel embedded(model, c.constraints.matrix(), c.constraints.free_vertices());
  SparseMatrixd K;
  embedded.stiffness(embedded.rest_positions(), K, false);
  std::vector<char> constrained(embedded.num_dofs(), 0);
  const VectorXd& rest = embedded.rest_positions();
  VectorXd f(embedded.num_dofs());
  for (Index q = 0; q < embedded.num_dof_vertices(); ++q) {
    const Vector3d X = rest.segment<3>(3 * q);
    if (X.x() == 0.0) constrained[3 * q] = constrained[3 * q + 1] = constrained[3 * q + 2] = 1;
    f.segment<3>(3 * q) = Vector3d(std::sin(3 * X.y()), 0.2, -1.0 - X.x() * X.z());
  }
  const DofReduction reduction(embedded.stiffness_pattern(), constrained);
  ClampedSystem system;
  reduction.restrict_matrix(K, system.A);
  system.b = reduction.restrict_vector(f);
  system.spaces = cut_nested_spaces(cut.tree(), c);
  system.free_dofs = reduction.free_dofs();
  system.hanging = c.constraints.num_hanging();
  return system;
}

struct SolveResult {
  VectorXd direct;
  VectorXd multigrid;
  long iterations = 0;
  int levels = 0;
  Index hanging = 0;
};

/// The clamped system of the cut by CHOLMOD and by multigrid-PCG (which must not fall back).
SolveResult solve_both(const ActiveCut& cut, double poisson_ratio,
                       const MultigridOptions& options = MultigridOptions()) {
  const ClampedSystem system = clamped_system(cut, poisson_ratio);
  SolveResult result;
  result.hanging = system.hanging;
  SpdSolver direct(LinearSolverKind::cholmod);
  EXPECT_TRUE(direct.solve(system.A, system.b, result.direct));
  if (options.single_precision_min_blocks == 0) {
    // The cut's levels are made of whole 3 × 3 blocks, so every level's cycle is rounded.
    MultigridPreconditioner cycle(free_dof_prolongations(system.spaces, system.free_dofs), options);
    EXPECT_TRUE(cycle.setup(system.A));
    for (int k = 1; k < cycle.num_levels(); ++k)
      EXPECT_TRUE(cycle.single_precision_products(k)) << "level " << k;
  }
  SpdSolver multigrid(LinearSolverKind::multigrid);
  multigrid.set_multigrid_options(options);
  multigrid.use_nested_spaces(&system.spaces, system.free_dofs);
  EXPECT_EQ(multigrid.kind(), LinearSolverKind::multigrid);
  EXPECT_TRUE(multigrid.solve(system.A, system.b, result.multigrid));
  EXPECT_EQ(multigrid.direct_fallbacks(), 0);  // solved by multigrid, not by CHOLMOD
  EXPECT_EQ(multigrid.kind(), LinearSolverKind::multigrid);
  result.iterations = multigrid.cg_iterations();
  result.levels = multigrid.multigrid_levels();
  return result;
}

TEST(CutMultigrid, ProlongationsInterpolateAffineFields) {
  TetTree tree(beam(), 3);
  const ActiveCut cut = graded_cut(tree, 1, 3);
  const ConstrainedCut c = flatten_cut(cut);
  ASSERT_GT(c.constraints.num_hanging(), 0);
  const NestedSpaces spaces = cut_nested_spaces(tree, c);
  ASSERT_GE(spaces.num_levels(), 2);
  spaces.check();
  // Positions of every space's vertices, through the injections from the finest down.
  const auto affine = [](const Vector3d& X) {
    return 0.3 * X.x() - 1.7 * X.y() + 0.4 * X.z() + 2.0;
  };
  std::vector<VectorXd> values(spaces.num_levels());
  std::vector<std::vector<Vector3d>> points(spaces.num_levels());
  const int finest = spaces.num_levels() - 1;
  for (const int v : c.constraints.free_vertices())
    points[finest].push_back(c.flat.mesh.vertices.row(v).transpose());
  for (int k = finest - 1; k >= 0; --k)
    for (const Index j : spaces.injections[k])
      points[k].push_back(points[k + 1][j]);
  for (int k = 0; k <= finest; ++k) {
    values[k].resize(static_cast<Index>(points[k].size()));
    for (std::size_t i = 0; i < points[k].size(); ++i)
      values[k][static_cast<Index>(i)] = affine(points[k][i]);
  }
  for (int k = 0; k < finest; ++k) {
    const VectorXd interpolated = spaces.prolongations[k] * values[k];
    EXPECT_LE((interpolated - values[k + 1]).lpNorm<Eigen::Infinity>(), 1e-12) << "level " << k;
  }
}

TEST(CutMultigrid, ReachesTheDirectSolution) {
  for (const double nu : {0.3, 0.49}) {
    TetTree tree(beam(), 3);
    struct Case {
      std::string name;
      ActiveCut cut;
    };
    std::vector<Case> cases;
    cases.push_back({"full", ActiveCut::uniform(tree, 3)});
    cases.push_back({"uniform level 2", ActiveCut::uniform(tree, 2)});
    cases.push_back({"adaptive 1..3", graded_cut(tree, 1, 3)});
    cases.push_back({"adaptive 0..2", graded_cut(tree, 0, 2)});
    for (const Case& test : cases) {
      // Also with every level's cycle products in single precision (on large levels only by
      // default): CG's own products stay double and reach the same solution.
      MultigridOptions single;
      single.single_precision_min_blocks = 0;
      long double_iterations = 0;
      for (const bool rounded : {false, true}) {
        const SolveResult r = solve_both(test.cut, nu, rounded ? single : MultigridOptions());
        const std::string label =
            test.name + " nu " + std::to_string(nu) + (rounded ? " single" : "");
        EXPECT_GE(r.levels, 2) << label;
        EXPECT_LE((r.multigrid - r.direct).norm(), 1e-8 * r.direct.norm()) << label;
        // The rounded cycle preconditions as well (measured: the same counts).
        if (rounded) {
          EXPECT_LE(r.iterations, double_iterations + 1) << label;
        } else {
          double_iterations = r.iterations;
        }
        if (test.name.rfind("adaptive", 0) == 0) {
          EXPECT_GT(r.hanging, 0) << label;
        }
        RecordProperty(label, std::to_string(r.iterations) + " iterations, " +
                                  std::to_string(r.levels) + " levels");
      }
    }
  }
}

// A thin plate (2 × 2 × 0.05 m on 8 × 8 × 1 coarse cells, aspect 40, clamped on one edge) at
// ν = 0.3, full and adaptive: multigrid alone (no CHOLMOD fallback) reaches the direct solution.
// Thin elements are hard for point smoothers: measured 98 (full) and 82 (adaptive) iterations.
// At ν = 0.49 the same plate took 310 / 250, and on 4 × 4 × 1 coarse cells (flatter coarse tets)
// the full cut reached the 500-iteration limit and fell back to CHOLMOD (README, Linear solvers).
TEST(CutMultigrid, ThinPlate) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 2.0, 0.05), {8, 8, 1}), 2);
  for (const bool adaptive : {false, true}) {
    const ActiveCut cut = adaptive ? graded_cut(tree, 0, 2) : ActiveCut::uniform(tree, 2);
    const SolveResult r = solve_both(cut, 0.3);
    EXPECT_LE((r.multigrid - r.direct).norm(), 1e-8 * r.direct.norm())
        << (adaptive ? "adaptive" : "full");
    EXPECT_LE(r.iterations, 150) << (adaptive ? "adaptive" : "full");
    RecordProperty(std::string("thin plate ") + (adaptive ? "adaptive" : "full"),
                   std::to_string(r.iterations) + " iterations");
  }
}

// A system multigrid-PCG does not solve within its iteration limit is solved by CHOLMOD.
TEST(CutMultigrid, FallsBackToCholmod) {
  TetTree tree(beam(), 2);
  const ClampedSystem system = clamped_system(ActiveCut::uniform(tree, 2), 0.3);
  const SparseMatrixd& A = system.A;
  const VectorXd& b = system.b;
  SpdSolver solver(LinearSolverKind::multigrid);
  solver.use_nested_spaces(&system.spaces, system.free_dofs);
  solver.set_max_iterations(2);
  VectorXd x;
  ASSERT_TRUE(solver.solve(A, b, x));
  EXPECT_EQ(solver.direct_fallbacks(), 1);
  EXPECT_LE((A * x - b).norm(), 1e-10 * b.norm());
  EXPECT_EQ(solver.kind(), LinearSolverKind::cholmod);  // A factorised: CHOLMOD from now on
  EXPECT_TRUE(solver.solve(A, b, x));
  EXPECT_EQ(solver.direct_fallbacks(), 1);
}

// An indefinite matrix (negative curvature) is refused, and multigrid stays for the next one; a
// nearby matrix reuses the hierarchy (no new setup); the solutions are the direct ones.
TEST(CutMultigrid, RefusesIndefiniteAndReusesTheHierarchy) {
  TetTree tree(beam(), 2);
  const ClampedSystem system = clamped_system(ActiveCut::uniform(tree, 2), 0.3);
  const SparseMatrixd& A = system.A;
  const VectorXd& b = system.b;
  SpdSolver solver(LinearSolverKind::multigrid);
  solver.use_nested_spaces(&system.spaces, system.free_dofs);
  VectorXd x;
  ASSERT_TRUE(solver.solve(A, b, x));
  EXPECT_EQ(solver.multigrid_setups(), 1);

  // 1 % stiffer: the same hierarchy serves.
  const SparseMatrixd A2 = 1.01 * A;
  ASSERT_TRUE(solver.solve(A2, b, x));
  EXPECT_EQ(solver.multigrid_setups(), 1);
  SpdSolver direct(LinearSolverKind::cholmod);
  VectorXd expected;
  ASSERT_TRUE(direct.solve(A2, b, expected));
  EXPECT_LE((x - expected).norm(), 1e-8 * expected.norm());

  // Indefinite: shift the spectrum below zero in part.
  double diagonal = 0.0;
  for (Index i = 0; i < A.rows(); ++i)
    diagonal = std::max(diagonal, A.coeff(i, i));
  SparseMatrixd I(A.rows(), A.rows());
  I.setIdentity();
  const SparseMatrixd indefinite = A - 0.3 * diagonal * I;
  EXPECT_FALSE(solver.solve(indefinite, b, x));
  EXPECT_EQ(solver.kind(), LinearSolverKind::multigrid);
  ASSERT_TRUE(solver.solve(A, b, x));
  ASSERT_TRUE(direct.solve(A, b, expected));
  EXPECT_LE((x - expected).norm(), 1e-8 * expected.norm());
}

// A cut change seeds the next cut's smoothers with the Lanczos estimates of the cut before
// (MultigridPreconditioner::seed_smoother_estimates). On two neighbouring cuts of the beam (the
// second refines a band next to the first's refined end) the seeded levels take the seeds as
// their estimates, those within 10 % of what Lanczos measures on the new cut, and multigrid-PCG
// on the seeded hierarchy reaches the direct solution in at most one iteration more than on a
// measured one. Levels whose sizes are off by more than a factor 2, or whose estimates are not
// positive and finite, measure their own, and a seed serves one setup.
TEST(CutMultigrid, SmootherEstimatesCarryOverToANeighbouringCut) {
  for (const double nu : {0.3, 0.49}) {
    SCOPED_TRACE("nu " + std::to_string(nu));
    TetTree tree(beam(), 3);
    const ActiveCut before = graded_cut(tree, 1, 3);
    ActiveCut after = before;
    for (const NodeId n : before.sorted_nodes()) {
      const double x = tree.tet_positions(n).row(0).minCoeff();
      if (tree.level(n) == 1 && x >= 0.6 && x < 1.0) after.refine(n);
    }
    ASSERT_GT(after.size(), before.size());
    const ClampedSystem old_system = clamped_system(before, nu);
    const ClampedSystem system = clamped_system(after, nu);

    SpdSolver old_solver(LinearSolverKind::multigrid);
    old_solver.use_nested_spaces(&old_system.spaces, old_system.free_dofs);
    EXPECT_TRUE(old_solver.smoother_estimates().empty());  // before any setup
    VectorXd x_old;
    ASSERT_TRUE(old_solver.solve(old_system.A, old_system.b, x_old));
    const std::vector<SmootherEstimate> seeds = old_solver.smoother_estimates();
    ASSERT_EQ(static_cast<int>(seeds.size()), old_solver.multigrid_levels() - 1);
    ASSERT_GT(seeds.size(), 1u);

    const std::vector<SparseMatrixd> prolongations =
        free_dof_prolongations(system.spaces, system.free_dofs);
    MultigridPreconditioner measured(prolongations);
    ASSERT_TRUE(measured.setup(system.A));
    EXPECT_FALSE(measured.seeded_setup());
    const std::vector<SmootherEstimate> own = measured.smoother_estimates();
    ASSERT_EQ(own.size(), seeds.size());
    MultigridPreconditioner seeded(prolongations);
    seeded.seed_smoother_estimates(seeds);
    ASSERT_TRUE(seeded.setup(system.A));
    EXPECT_TRUE(seeded.seeded_setup());
    const std::vector<SmootherEstimate> taken = seeded.smoother_estimates();
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      SCOPED_TRACE("level " + std::to_string(k + 1));
      ASSERT_TRUE(2 * seeds[k].rows >= own[k].rows && seeds[k].rows <= 2 * own[k].rows);
      // The seed and the unknowns it was measured on pass on as they came.
      EXPECT_EQ(taken[k].lambda, seeds[k].lambda);
      EXPECT_EQ(taken[k].rows, seeds[k].rows);
      EXPECT_NEAR(seeds[k].lambda, own[k].lambda, 0.1 * own[k].lambda);
      EXPECT_EQ(seeded.smoother_interval(static_cast<int>(k) + 1).first,
                MultigridOptions().chebyshev_lower * seeds[k].lambda);
    }
    // Used by one setup: the next measures.
    ASSERT_TRUE(seeded.setup(system.A));
    EXPECT_FALSE(seeded.seeded_setup());
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      EXPECT_EQ(seeded.smoother_estimates()[k].lambda, own[k].lambda);
      EXPECT_EQ(seeded.smoother_estimates()[k].rows, own[k].rows);
    }

    SpdSolver direct(LinearSolverKind::cholmod);
    VectorXd x_direct;
    ASSERT_TRUE(direct.solve(system.A, system.b, x_direct));
    long iterations[2] = {0, 0};
    for (const bool seed : {false, true}) {
      SpdSolver solver(LinearSolverKind::multigrid);
      solver.use_nested_spaces(&system.spaces, system.free_dofs,
                               seed ? seeds : std::vector<SmootherEstimate>{});
      VectorXd x;
      ASSERT_TRUE(solver.solve(system.A, system.b, x));
      EXPECT_EQ(solver.direct_fallbacks(), 0);
      EXPECT_EQ(solver.multigrid_setups(), 1);
      EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm()) << (seed ? "seeded" : "measured");
      iterations[seed ? 1 : 0] = solver.cg_iterations();
      for (std::size_t k = 0; k < seeds.size(); ++k)
        EXPECT_EQ(solver.smoother_estimates()[k].lambda, seed ? seeds[k].lambda : own[k].lambda);
    }
    EXPECT_LE(iterations[1], iterations[0] + 1);
    RecordProperty("nu " + std::to_string(nu), std::to_string(iterations[0]) + " measured, " +
                                                   std::to_string(iterations[1]) + " seeded, " +
                                                   std::to_string(seeds.size()) + " levels");

    // Level by level: a seed for a level a third the size of the first is not taken there, the
    // others are.
    std::vector<SmootherEstimate> mixed = seeds;
    mixed[0].rows = own[0].rows / 3;
    MultigridPreconditioner partly(prolongations);
    partly.seed_smoother_estimates(mixed);
    ASSERT_TRUE(partly.setup(system.A));
    EXPECT_TRUE(partly.seeded_setup());
    for (std::size_t k = 0; k < seeds.size(); ++k)
      EXPECT_EQ(partly.smoother_estimates()[k].lambda, k == 0 ? own[k].lambda : seeds[k].lambda)
          << "level " << k + 1;
    // Estimates that are not positive and finite are not taken.
    for (const double unusable : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
      std::vector<SmootherEstimate> bad = seeds;
      bad.back().lambda = unusable;
      MultigridPreconditioner cycle(prolongations);
      cycle.seed_smoother_estimates(bad);
      ASSERT_TRUE(cycle.setup(system.A));
      EXPECT_EQ(cycle.smoother_estimates().back().lambda, own.back().lambda);
      EXPECT_EQ(cycle.smoother_estimates().front().lambda, seeds.front().lambda);
    }
    // Seeds for another number of levels are not used.
    MultigridPreconditioner fewer(prolongations);
    fewer.seed_smoother_estimates({seeds.front()});
    ASSERT_TRUE(fewer.setup(system.A));
    EXPECT_FALSE(fewer.seeded_setup());
    EXPECT_EQ(fewer.smoother_estimates().front().lambda, own.front().lambda);
  }
}

// A seed far above a level's spectrum is held to the level's row-sum bound, a valid but loose
// upper end: PCG then needs more iterations. With the iteration limit at what the measured
// hierarchy needs, the seeded hierarchy does not converge, and the solver sets up again with
// measured estimates before it asks CHOLMOD.
TEST(CutMultigrid, ASeededHierarchyThatDoesNotConvergeIsSetUpAgainMeasured) {
  TetTree tree(beam(), 3);
  const ClampedSystem system = clamped_system(graded_cut(tree, 1, 3), 0.3);
  SpdSolver direct(LinearSolverKind::cholmod);
  VectorXd x_direct;
  ASSERT_TRUE(direct.solve(system.A, system.b, x_direct));

  SpdSolver measured(LinearSolverKind::multigrid);
  measured.use_nested_spaces(&system.spaces, system.free_dofs);
  VectorXd x;
  ASSERT_TRUE(measured.solve(system.A, system.b, x));
  const long needed = measured.cg_iterations();
  std::vector<SmootherEstimate> high = measured.smoother_estimates();
  for (SmootherEstimate& estimate : high)
    estimate.lambda *= 100.0;

  SpdSolver solver(LinearSolverKind::multigrid);
  solver.set_max_iterations(static_cast<int>(needed));
  solver.use_nested_spaces(&system.spaces, system.free_dofs, high);
  ASSERT_TRUE(solver.solve(system.A, system.b, x));
  EXPECT_EQ(solver.multigrid_setups(), 2);  // seeded, then measured
  EXPECT_EQ(solver.direct_fallbacks(), 0);
  EXPECT_EQ(solver.kind(), LinearSolverKind::multigrid);
  EXPECT_GT(solver.cg_iterations(), needed);  // the seeded attempt's and the measured solve's
  EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm());
  const std::vector<SmootherEstimate> now = solver.smoother_estimates();
  const std::vector<SmootherEstimate> own = measured.smoother_estimates();
  for (std::size_t k = 0; k < own.size(); ++k)
    EXPECT_EQ(now[k].lambda, own[k].lambda);
}

/// Level 2 everywhere, level 3 where x < `x_fine`: cuts whose coarse spaces (the vertices of
/// levels ≤ 2, none of them hanging) are the same for every `x_fine`.
ActiveCut band_cut(TetTree& tree, double x_fine) {
  ActiveCut cut = ActiveCut::uniform(tree, 2);
  for (const NodeId n : cut.sorted_nodes())
    if (tree.tet_positions(n).row(0).minCoeff() < x_fine) cut.refine(n);
  return cut;
}

// A cut change whose new cut has the same coarse spaces carries the coarse levels over
// (MultigridPreconditioner::release_coarse_levels, offer_coarse_levels): the new hierarchy sets up
// only its finest level, and multigrid-PCG on it reaches the direct solution of the new cut.
TEST(CutMultigrid, CoarseLevelsCarryOverToACutWithTheSameCoarseSpaces) {
  for (const double nu : {0.3, 0.49}) {
    SCOPED_TRACE("nu " + std::to_string(nu));
    TetTree tree(beam(), 3);
    const ClampedSystem old_system = clamped_system(band_cut(tree, 0.4), nu);
    const ClampedSystem system = clamped_system(band_cut(tree, 0.9), nu);
    ASSERT_GT(system.A.rows(), old_system.A.rows());
    ASSERT_EQ(system.spaces.num_levels(), 4);
    EXPECT_EQ(system.spaces.keys, old_system.spaces.keys);
    std::vector<std::vector<std::int64_t>> keys, old_keys;
    free_dof_prolongations(system.spaces, system.free_dofs, &keys);
    free_dof_prolongations(old_system.spaces, old_system.free_dofs, &old_keys);
    EXPECT_FALSE(keys.empty());
    EXPECT_EQ(keys, old_keys);

    SpdSolver old_solver(LinearSolverKind::multigrid);
    old_solver.use_nested_spaces(&old_system.spaces, old_system.free_dofs);
    EXPECT_EQ(old_solver.release_coarse_levels(), nullptr);  // before any setup
    VectorXd x;
    ASSERT_TRUE(old_solver.solve(old_system.A, old_system.b, x));
    const std::vector<SmootherEstimate> seeds = old_solver.smoother_estimates();
    std::shared_ptr<MultigridCoarseLevels> levels = old_solver.release_coarse_levels();
    ASSERT_NE(levels, nullptr);
    // The solver that gave them up sets up anew and still solves its system.
    VectorXd x_old;
    SpdSolver old_direct(LinearSolverKind::cholmod);
    ASSERT_TRUE(old_direct.solve(old_system.A, old_system.b, x_old));
    ASSERT_TRUE(old_solver.solve(old_system.A, old_system.b, x));
    EXPECT_EQ(old_solver.multigrid_setups(), 2);
    EXPECT_EQ(old_solver.carried_setups(), 0);
    EXPECT_LE((x - x_old).norm(), 1e-8 * x_old.norm());

    SpdSolver direct(LinearSolverKind::cholmod);
    VectorXd x_direct;
    ASSERT_TRUE(direct.solve(system.A, system.b, x_direct));
    long iterations[2] = {0, 0};
    for (const bool carry : {false, true}) {
      SpdSolver solver(LinearSolverKind::multigrid);
      solver.use_nested_spaces(&system.spaces, system.free_dofs, seeds,
                               carry ? levels : std::shared_ptr<MultigridCoarseLevels>{});
      ASSERT_TRUE(solver.solve(system.A, system.b, x));
      EXPECT_EQ(solver.multigrid_setups(), 1);
      EXPECT_EQ(solver.carried_setups(), carry ? 1 : 0);
      EXPECT_EQ(solver.direct_fallbacks(), 0);
      EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm()) << (carry ? "carried" : "own");
      iterations[carry ? 1 : 0] = solver.cg_iterations();
    }
    // The coarse operators of a nearby cut precondition about as well as the cut's own.
    EXPECT_LE(iterations[1], iterations[0] + 3);
    RecordProperty("nu " + std::to_string(nu), std::to_string(iterations[0]) + " own, " +
                                                   std::to_string(iterations[1]) + " carried");
    // Taken once: offered again, they are not there to take.
    SpdSolver again(LinearSolverKind::multigrid);
    again.use_nested_spaces(&system.spaces, system.free_dofs, seeds, levels);
    ASSERT_TRUE(again.solve(system.A, system.b, x));
    EXPECT_EQ(again.carried_setups(), 0);
    EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm());
  }
}

// A solver on carried coarse levels judges them against the hierarchy that computed them. Levels
// of a ν = 0.3 beam carried to a ν = 0.49 beam on cuts with the same coarse spaces precondition it
// poorly: the first solve needs more than twice the iterations per decade that the ν = 0.3
// hierarchy needed, so the solver marks the hierarchy stale (and gives nothing up) and sets up
// its own at the next solve. With the iteration limit at what the ν = 0.49 beam's own hierarchy
// needs, the carried hierarchy does not converge, and the solver sets up its own before it asks
// CHOLMOD.
TEST(CutMultigrid, ACarriedHierarchyIsJudgedAgainstTheOneThatComputedItsLevels) {
  TetTree tree(beam(), 3);
  const ClampedSystem old_system = clamped_system(band_cut(tree, 0.4), 0.3);
  const ClampedSystem system = clamped_system(band_cut(tree, 0.9), 0.49);
  ASSERT_EQ(system.spaces.keys, old_system.spaces.keys);
  SpdSolver direct(LinearSolverKind::cholmod);
  VectorXd x_direct, x;
  ASSERT_TRUE(direct.solve(system.A, system.b, x_direct));
  const auto carried_levels = [&] {
    SpdSolver old_solver(LinearSolverKind::multigrid);
    old_solver.use_nested_spaces(&old_system.spaces, old_system.free_dofs);
    VectorXd x_old;
    EXPECT_TRUE(old_solver.solve(old_system.A, old_system.b, x_old));
    RecordProperty("nu 0.3 hierarchy", std::to_string(old_solver.cg_iterations()) + " iterations");
    return old_solver.release_coarse_levels();
  };
  SpdSolver own(LinearSolverKind::multigrid);
  own.use_nested_spaces(&system.spaces, system.free_dofs);
  ASSERT_TRUE(own.solve(system.A, system.b, x));
  const long own_iterations = own.cg_iterations();

  SpdSolver solver(LinearSolverKind::multigrid);
  solver.use_nested_spaces(&system.spaces, system.free_dofs, {}, carried_levels());
  ASSERT_TRUE(solver.solve(system.A, system.b, x));
  EXPECT_EQ(solver.carried_setups(), 1);
  EXPECT_EQ(solver.multigrid_setups(), 1);
  EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm());
  const long carried_iterations = solver.cg_iterations();
  RecordProperty("nu 0.49 on carried levels", std::to_string(carried_iterations) + " iterations, " +
                                                  std::to_string(own_iterations) + " on its own");
  EXPECT_EQ(solver.release_coarse_levels(), nullptr);  // stale: nothing to give up
  ASSERT_TRUE(solver.solve(system.A, system.b, x));
  EXPECT_EQ(solver.multigrid_setups(), 2);
  EXPECT_EQ(solver.carried_setups(), 1);
  EXPECT_EQ(solver.cg_iterations() - carried_iterations, own_iterations);
  EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm());

  SpdSolver limited(LinearSolverKind::multigrid);
  limited.set_max_iterations(static_cast<int>(own_iterations));
  limited.use_nested_spaces(&system.spaces, system.free_dofs, {}, carried_levels());
  ASSERT_TRUE(limited.solve(system.A, system.b, x));
  EXPECT_EQ(limited.multigrid_setups(), 2);  // carried, then its own
  EXPECT_EQ(limited.carried_setups(), 1);
  EXPECT_EQ(limited.direct_fallbacks(), 0);
  EXPECT_EQ(limited.kind(), LinearSolverKind::multigrid);
  EXPECT_LE((x - x_direct).norm(), 1e-8 * x_direct.norm());
}

// The V-cycle of a hierarchy on carried coarse levels is the cycle of the system they came from
// with the new finest operator, bit for bit: on one cut, levels set up on A and carried to 2A
// give the cycle of a hierarchy set up on A and then updated to 2A (update_finest), and not that
// of a hierarchy set up on 2A (whose coarse operators are twice as large). Levels whose keys or
// prolongations differ from the hierarchy's own are not taken.
TEST(CutMultigrid, ACarriedCycleIsThePreviousSystemsCoarseLevelsUnderTheNewFinest) {
  TetTree tree(beam(), 3);
  const ClampedSystem system = clamped_system(band_cut(tree, 0.6), 0.3);
  const SparseMatrixd& A = system.A;
  const SparseMatrixd A2 = 2.0 * A;
  std::vector<std::vector<std::int64_t>> keys;
  const std::vector<SparseMatrixd> prolongations =
      free_dof_prolongations(system.spaces, system.free_dofs, &keys);
  ASSERT_EQ(keys.size(), prolongations.size());
  ASSERT_GE(prolongations.size(), 2u);
  const MultigridOptions options;
  const auto give_up_levels = [&](double rate) {
    MultigridPreconditioner giver(prolongations, options, keys);
    EXPECT_TRUE(giver.setup(A));
    return giver.release_coarse_levels(rate);
  };
  const auto cycle = [&](const MultigridPreconditioner& m) {
    VectorXd r(A.rows()), z;
    for (Index i = 0; i < r.size(); ++i)
      r[i] = std::sin(0.37 * static_cast<double>(i));
    m.apply(r, z);
    return z;
  };
  MultigridPreconditioner reference(prolongations, options, keys);
  ASSERT_TRUE(reference.setup(A));
  const std::vector<SmootherEstimate> estimates = reference.smoother_estimates();
  reference.update_finest(A2);
  MultigridPreconditioner own(prolongations, options, keys);
  ASSERT_TRUE(own.setup(A2));

  MultigridPreconditioner carried(prolongations, options, keys);
  carried.offer_coarse_levels(give_up_levels(7.5));
  carried.seed_smoother_estimates(estimates);  // D⁻¹A and its spectrum do not scale with A
  ASSERT_TRUE(carried.setup(A2));
  EXPECT_TRUE(carried.carried_setup());
  EXPECT_EQ(carried.carried_iterations_per_decade(), 7.5);
  EXPECT_EQ(carried.level_sizes(), reference.level_sizes());
  const VectorXd z = cycle(carried);
  EXPECT_EQ((z - cycle(reference)).lpNorm<Eigen::Infinity>(), 0.0);
  EXPECT_GT((z - cycle(own)).norm(), 1e-3 * z.norm());
  // The next setup computes its own levels.
  ASSERT_TRUE(carried.setup(A2));
  EXPECT_FALSE(carried.carried_setup());
  EXPECT_EQ(carried.carried_iterations_per_decade(), -1.0);
  EXPECT_EQ((cycle(carried) - cycle(own)).lpNorm<Eigen::Infinity>(), 0.0);

  // Other keys, or another prolongation between the coarse levels: not taken.
  std::vector<std::vector<std::int64_t>> other_keys = keys;
  other_keys[1][0] += 3;
  std::vector<SparseMatrixd> other_prolongations = prolongations;
  double& weight = other_prolongations[0].valuePtr()[0];
  weight = std::nextafter(weight, 2.0 * weight);  // one ulp away
  for (const bool by_keys : {true, false}) {
    SCOPED_TRACE(by_keys ? "keys" : "prolongation");
    MultigridPreconditioner m(by_keys ? prolongations : other_prolongations, options,
                              by_keys ? other_keys : keys);
    m.offer_coarse_levels(give_up_levels(-1.0));
    ASSERT_TRUE(m.setup(A2));
    EXPECT_FALSE(m.carried_setup());
    if (by_keys) {
      EXPECT_EQ((cycle(m) - cycle(own)).lpNorm<Eigen::Infinity>(), 0.0);
    }
  }
  // Without keys nothing is given up or taken.
  MultigridPreconditioner keyless(prolongations, options);
  ASSERT_TRUE(keyless.setup(A));
  EXPECT_EQ(keyless.release_coarse_levels(), nullptr);
  keyless.offer_coarse_levels(give_up_levels(-1.0));
  ASSERT_TRUE(keyless.setup(A2));
  EXPECT_FALSE(keyless.carried_setup());
}

// Deterministic PCG iteration counts (relative residual 10⁻¹⁰) of uniform cuts at levels 1–3:
// measured 17, 21, 24 at ν = 0.3 and 42, 54, 63 at ν = 0.49. Bound: each level at most 1.35×
// the previous one plus one, and at most 30 / 75 iterations.
TEST(CutMultigrid, IterationsStayBoundedUnderRefinement) {
  for (const double nu : {0.3, 0.49}) {
    std::vector<long> iterations;
    for (int level = 1; level <= 3; ++level) {
      TetTree tree(beam(), level);
      iterations.push_back(solve_both(ActiveCut::uniform(tree, level), nu).iterations);
      RecordProperty("nu " + std::to_string(nu) + " level " + std::to_string(level),
                     std::to_string(iterations.back()));
    }
    for (std::size_t k = 1; k < iterations.size(); ++k)
      EXPECT_LE(iterations[k], 1.35 * iterations[k - 1] + 1) << "nu " << nu << " level " << k + 1;
    EXPECT_LE(iterations.back(), nu < 0.4 ? 30 : 75) << "nu " << nu;
  }
}

// A whole run: the multigrid solver gives the CHOLMOD run's states (to Newton tolerance) on a
// full and a uniform cut, static and backward Euler, and the run reports it used multigrid.
TEST(CutMultigrid, RunsMatchCholmod) {
  const TetMesh coarse = beam();
  Material rubber;
  rubber.model = MaterialModel::neohookean;
  rubber.youngs_modulus = 1e5;
  rubber.poisson_ratio = 0.3;
  rubber.density = 1000.0;
  DirichletSpec clamp;
  clamp.name = "fixed.0";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  for (const bool dynamic : {false, true})
    for (const HierarchyMode mode : {HierarchyMode::full, HierarchyMode::uniform}) {
      HierarchySettings hierarchy;
      hierarchy.levels = 2;
      hierarchy.mode = mode;
      hierarchy.level = 1;
      SolverSettings solver;
      solver.mode = dynamic ? SimulationMode::dynamic : SimulationMode::static_equilibrium;
      solver.dt = 5e-3;
      solver.duration = 0.05;
      solver.load_steps = 3;
      SCOPED_TRACE(std::string(dynamic ? "dynamic " : "static ") + to_string(mode));
      auto run = [&](LinearSolverKind kind) {
        solver.newton.linear_solver = kind;
        AdaptiveSimulation sim(
            coarse, hierarchy,
            {.material = rubber, .dirichlet = {clamp}, .gravity = Vector3d(0.0, 0.0, -9.81)},
            solver);
        while (!sim.finished())
          sim.advance();
        EXPECT_EQ(sim.counters().linear_solver, kind);
        EXPECT_EQ(sim.counters().multigrid_direct_fallbacks, 0);
        return VectorXd(sim.simulation().positions() - flatten(sim.simulation().mesh().vertices));
      };
      const VectorXd direct = run(LinearSolverKind::cholmod);
      const VectorXd multigrid = run(LinearSolverKind::multigrid);
      const std::string label = std::string(dynamic ? "dynamic " : "static ") +
                                (mode == HierarchyMode::full ? "full" : "uniform");
      ASSERT_GT(direct.lpNorm<Eigen::Infinity>(), 1e-4) << label;
      EXPECT_LE((multigrid - direct).lpNorm<Eigen::Infinity>(),
                1e-7 * direct.lpNorm<Eigen::Infinity>())
          << label;
    }
}

}  // namespace
}  // namespace strata
