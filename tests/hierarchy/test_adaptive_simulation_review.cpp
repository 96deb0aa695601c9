// Findings of a second read of the adaptive driver, kept as regression tests: momentum at
// coarsening, the static energy record with prescribed motion, overlapping Dirichlet groups on a
// cut, and the explicit step limit when fixed regions force refinement.
#include <gtest/gtest.h>

#include "adaptive_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/region.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/finest_level.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {
namespace {

Vector3d momentum(const Simulation& sim) {
  Vector3d p = Vector3d::Zero();
  const VectorXd& v = sim.dof_velocities();
  for (Index q = 0; q < sim.dof_vertex_mass().size(); ++q)
    p += sim.dof_vertex_mass()[q] * v.segment<3>(3 * q);
  return p;
}

/// Runs `adaptive` and a plain Simulation on its initial (level-1) mesh side by side for five
/// steps, up to the first cut change (everything merges back to the roots).
struct CoarseningRun {
  Vector3d p_before, p_after;
  double ke_before = 0.0, ke_after = 0.0;
};

CoarseningRun coarsen_after_five_steps(const std::vector<DirichletSpec>& fixed,
                                       const std::vector<RegionLoad>& loads,
                                       const Vector3d& gravity) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.25, 0.25), {4, 1, 1});
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 2e-3;
  settings.duration = 0.02;
  HierarchySettings h = testing::hierarchy(1, HierarchyMode::adaptive, 1);
  h.adapt_every = 5;
  h.criteria.refine_threshold = 1e30;
  h.criteria.coarsen_indicator_fraction = 1.0;
  h.criteria.coarsen_tolerance = 1e6;
  h.criteria.min_steps_between_changes = 0;
  AdaptiveSimulation adaptive(
      coarse, h,
      {.material = testing::rubber(), .dirichlet = fixed, .loads = loads, .gravity = gravity},
      settings);
  // Independent reference for the state just before the change: the same level-1 mesh.
  Simulation reference(
      adaptive.flat().mesh,
      {.material = testing::rubber(), .dirichlet = fixed, .loads = loads, .gravity = gravity},
      settings);
  for (int k = 0; k < 5; ++k) {
    adaptive.advance();
    reference.advance();
  }
  EXPECT_EQ(adaptive.changes().size(), 1u);
  EXPECT_GT(adaptive.changes().at(0).coarsened, 0);
  return {momentum(reference), momentum(adaptive.simulation()), reference.kinetic_energy(),
          adaptive.simulation().kinetic_energy()};
}

TEST(AdaptiveSimulationReview, CoarseningKeepsMomentumAndKineticEnergyOfAFreeBody) {
  // No prescribed vertex: the free mass is the same on every cut, so both can be kept exactly.
  RegionLoad push;
  push.name = "forces.0";
  push.region = BoxRegion{Vector3d(1, -1, -1), Vector3d(1, 1, 1)};
  push.total_force = Vector3d(0, 50.0, -200.0);
  const CoarseningRun run = coarsen_after_five_steps({}, {push}, Vector3d::Zero());
  EXPECT_GT(run.p_before.norm(), 0.0);
  EXPECT_LT((run.p_after - run.p_before).norm(), 1e-9 * run.p_before.norm());
  EXPECT_NEAR(run.ke_after, run.ke_before, 1e-9 * run.ke_before);
}

TEST(AdaptiveSimulationReview, CoarseningNeverAddsKineticEnergyNextToAClamp) {
  // The clamped vertices take over lumped mass on the coarse cut: the free DOFs cannot keep both;
  // the kinetic energy is kept and the momentum keeps its direction without growing.
  const CoarseningRun run = coarsen_after_five_steps(
      {testing::fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitX())}, {},
      Vector3d(0, 0, -9.81));
  EXPECT_NEAR(run.ke_after, run.ke_before, 1e-9 * run.ke_before);
  EXPECT_LE(run.p_after.norm(), run.p_before.norm() * (1 + 1e-12));
  EXPECT_GT(run.p_after.normalized().dot(run.p_before.normalized()), 1 - 1e-9);
}

// (2) Static restart: Dirichlet DOFs reset to the previous load factor by set_state, so the
// recorded energy_after of a pure refinement is not the energy of the transferred state.
TEST(AdaptiveSimulationReview, StaticRefinementRecordKeepsEnergyWithPrescribedDisplacement) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.25), {4, 4, 1});
  DirichletSpec lift = testing::fixed_plane("lift.0", Vector3d::Zero(), Vector3d::UnitZ());
  lift.kind = DirichletKind::displacement;
  lift.displacement = Vector3d(0, 0, 0.003);
  RegionLoad load;
  load.name = "forces.0";
  load.region = BoxRegion{Vector3d(0.4, 0.4, 0.25), Vector3d(0.6, 0.6, 0.25)};
  load.total_force = Vector3d(0, 0, -500.0);
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 2;
  AdaptiveSimulation sim(coarse, testing::hierarchy(2, HierarchyMode::adaptive, 0),
                         {.material = testing::rubber(), .dirichlet = {lift}, .loads = {load}},
                         settings);
  while (!sim.finished())
    sim.advance();
  ASSERT_FALSE(sim.changes().empty());
  for (const CutChangeRecord& change : sim.changes()) {
    if (change.coarsened == 0) {
      EXPECT_NEAR(change.energy_after, change.energy_before, 1e-9 * change.energy_before);
    }
  }
}

// (3) Overlapping Dirichlet groups: the later group owns the shared vertices, but the exactness
// rule tests each region on its own, so finest points of the earlier group next to the later one
// are interpolated from the later group's corners.
TEST(AdaptiveSimulationReview, OverlappingGroupsStayExactOnTheCut) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.5), {2, 2, 1});
  std::vector<DirichletSpec> groups = {
      testing::fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitZ())};
  DirichletSpec slide;
  slide.name = "prescribed.0";
  slide.region = BoxRegion{Vector3d(0.125, 0.125, 0.0), Vector3d(0.375, 0.375, 0.0)};
  slide.kind = DirichletKind::displacement;
  slide.displacement = Vector3d(0.01, 0, 0);
  groups.push_back(slide);
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 1;
  // Finest lattice points of the bottom face (spacing 1/16) strictly outside the patch.
  std::vector<Vector3d> points;
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j) {
      const Vector3d p(i / 16.0, j / 16.0, 0.0);
      const bool in_patch = p.x() >= 0.125 && p.x() <= 0.375 && p.y() >= 0.125 && p.y() <= 0.375;
      if (!in_patch) points.push_back(p);
    }
  MatrixX3d probes(static_cast<Index>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k)
    probes.row(static_cast<Index>(k)) = points[k].transpose();
  for (const HierarchyMode mode : {HierarchyMode::full, HierarchyMode::uniform}) {
    AdaptiveSimulation sim(coarse, testing::hierarchy(3, mode, 0),
                           {.material = testing::rubber(), .dirichlet = groups}, settings);
    while (!sim.finished())
      sim.advance();
    const MatrixX3d u = sim.displacements(sim.locate(probes, "probes", 1e-9));
    int moved = 0;
    double worst = 0.0;
    for (Index k = 0; k < u.rows(); ++k) {
      worst = std::max(worst, u.row(k).norm());
      if (u.row(k).norm() > 1e-12) ++moved;
    }
    EXPECT_EQ(moved, 0) << to_string(mode);
  }
}

// Explicit integrator: when exact fixed/prescribed regions need a level whose stable step is
// below dt, the run is refused up front (it would otherwise diverge within a few steps).
TEST(AdaptiveSimulationReview, ExplicitRunNeverStartsBelowItsStableStep) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.5), {2, 2, 1});
  std::vector<DirichletSpec> groups = {
      testing::fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitZ())};
  DirichletSpec push;
  push.name = "prescribed.0";
  push.region = BoxRegion{Vector3d(0.125, 0.125, 0.5), Vector3d(0.375, 0.375, 0.5)};
  push.kind = DirichletKind::displacement;
  push.displacement = Vector3d(0, 0, -0.01);
  groups.push_back(push);
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.dt = 1.0;
  settings.duration = 1.0;
  const double coarse_dt =
      Simulation(coarse, {.material = testing::rubber()}, settings).stable_dt_estimate();
  settings.dt = 0.9 * coarse_dt;
  settings.duration = 400 * settings.dt;
  EXPECT_THROW(AdaptiveSimulation(coarse, testing::hierarchy(3, HierarchyMode::adaptive, 0),
                                  {.material = testing::rubber(), .dirichlet = groups}, settings),
               InputError);
  // Small enough a step: the run starts on the refined cut, above its stable step, and stays
  // finite.
  settings.dt = 0.1 * coarse_dt;
  settings.duration = 50 * settings.dt;
  AdaptiveSimulation sim(coarse, testing::hierarchy(3, HierarchyMode::adaptive, 0),
                         {.material = testing::rubber(), .dirichlet = groups}, settings);
  EXPECT_GT(sim.cut().finest_level(), 0);
  EXPECT_GE(sim.simulation().stable_dt_estimate(), settings.dt);
  EXPECT_NO_THROW(while (!sim.finished()) sim.advance());
}

}  // namespace
}  // namespace strata
