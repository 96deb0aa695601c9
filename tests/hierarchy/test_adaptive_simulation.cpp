// The multiresolution driver: full and uniform modes against core's Simulation on the same meshes
// (independent path), finest-level loads and Dirichlet regions, adaptive accuracy against the full
// resolution, energy at refinement, and the explicit step limit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "adaptive_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/region.hpp"
#include "strata/core/sim/stable_time_step.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/finest_level.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {
namespace {

using testing::box_load;
using testing::fixed_plane;
using testing::hierarchy;
using testing::rubber;

SolverSettings static_settings(int load_steps) {
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = load_steps;
  return settings;
}

/// A 1 × 0.25 × 0.25 bar clamped at x = 0 with a shear load on its end face.
struct Bar {
  TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.25, 0.25), {4, 1, 1});
  std::vector<DirichletSpec> fixed = {fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitX())};
  std::vector<RegionLoad> loads = {
      box_load(Vector3d(1, -1, -1), Vector3d(1, 1, 1), Vector3d(0, 0, -200.0))};
  Vector3d gravity = Vector3d(0, 0, -9.81);
};

template <typename Sim>
void run(Sim& sim) {
  while (!sim.finished())
    sim.advance();
}

/// The adaptive run's deformed positions in the vertex order of `reference` (a mesh with the
/// same vertices, numbered its own way), matched by identical rest positions; empty if a vertex
/// has no match.
VectorXd in_reference_order(const AdaptiveSimulation& adaptive, const TetMesh& reference) {
  std::map<std::array<double, 3>, Index> index;
  for (Index v = 0; v < reference.vertices.rows(); ++v)
    index[{reference.vertices(v, 0), reference.vertices(v, 1), reference.vertices(v, 2)}] = v;
  const MatrixX3d& rest = adaptive.flat().mesh.vertices;
  const VectorXd& x = adaptive.simulation().positions();
  if (rest.rows() != reference.vertices.rows()) return {};
  VectorXd ordered(x.size());
  for (Index v = 0; v < rest.rows(); ++v) {
    const auto found = index.find({rest(v, 0), rest(v, 1), rest(v, 2)});
    if (found == index.end()) return {};
    ordered.segment<3>(3 * found->second) = x.segment<3>(3 * v);
  }
  return ordered;
}

TEST(AdaptiveSimulation, FullModeEqualsCoreOnTheLeafMesh) {
  const Bar bar;
  AdaptiveSimulation adaptive(
      bar.coarse, hierarchy(1, HierarchyMode::full),
      {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads, .gravity = bar.gravity},
      static_settings(2));
  run(adaptive);
  // Independent path: core's Simulation on the flattened leaves, loads spread by core itself.
  TetTree tree(bar.coarse, 1);
  for (NodeId r = 0; r < tree.num_roots(); ++r)
    tree.refine(r);
  const FlatTreeMesh leaves = flatten_leaves(tree);
  Simulation reference(
      leaves.mesh,
      {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads, .gravity = bar.gravity},
      static_settings(2));
  run(reference);
  ASSERT_EQ(adaptive.flat().mesh.tets.rows(), leaves.mesh.tets.rows());
  ASSERT_EQ(adaptive.constraints().num_hanging(), 0);
  const MatrixX3d probe = (MatrixX3d(1, 3) << 1.0, 0.125, 0.125).finished();
  const MatrixX3d u = adaptive.displacements(adaptive.locate(probe, "probes", 1e-9));
  // The same vertices, numbered by the cut's flattening: compared vertex by vertex.
  const VectorXd x = in_reference_order(adaptive, leaves.mesh);
  ASSERT_EQ(x.size(), reference.positions().size());
  EXPECT_LT((x - reference.positions()).lpNorm<Eigen::Infinity>(), 1e-9 * std::abs(u(0, 2)));
  EXPECT_LT(u(0, 2), -1e-3);
}

TEST(AdaptiveSimulation, UniformCoarseLevelEqualsCoreOnTheCoarseMesh) {
  // Loads spread on the finest level of a 2-level tree and carried to the roots equal core's
  // spreading on the coarse mesh for a load on whole coarse faces (a uniform traction's lumped
  // loads are consistent, and consistent loads nest).
  const Bar bar;
  AdaptiveSimulation adaptive(
      bar.coarse, hierarchy(2, HierarchyMode::uniform, 0),
      {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads, .gravity = bar.gravity},
      static_settings(2));
  run(adaptive);
  Simulation reference(
      bar.coarse,
      {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads, .gravity = bar.gravity},
      static_settings(2));
  run(reference);
  ASSERT_EQ(adaptive.flat().mesh.tets.rows(), bar.coarse.tets.rows());
  const double scale = (reference.positions() - reference.model().rest_positions()).norm();
  const VectorXd x = in_reference_order(adaptive, bar.coarse);
  ASSERT_EQ(x.size(), reference.positions().size());
  EXPECT_LT((x - reference.positions()).norm(), 1e-9 * scale);
}

TEST(FinestLevelLoads, TotalForceIsKeptOnEveryCut) {
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.5), {2, 2, 1});
  TetTree tree(coarse, 3);
  // A patch inside one coarse face (no coarse vertex in it).
  const std::vector<RegionLoad> loads = {
      box_load(Vector3d(0.1, 0.1, 0.5), Vector3d(0.3, 0.2, 0.5), Vector3d(1.0, -2.0, -30.0))};
  const std::vector<PointLoad> points =
      finest_level_loads(tree, loads, region_tolerance(coarse.vertices));
  ASSERT_FALSE(points.empty());
  for (int level = 0; level <= 3; ++level) {
    ActiveCut cut = ActiveCut::uniform(tree, level);
    const FlatTreeMesh flat = flatten_nodes(tree, cut.nodes());
    const VectorXd f = map_point_loads(cut, flat, points);
    Vector3d total = Vector3d::Zero();
    for (Index v = 0; v < f.size() / 3; ++v)
      total += f.segment<3>(3 * v);
    EXPECT_LT((total - loads[0].total_force).norm(), 1e-12 * 30.0) << "level " << level;
    // Only vertices of the loaded face's plane carry load, and some coarse vertex does at level 0.
    for (Index v = 0; v < f.size() / 3; ++v)
      if (f.segment<3>(3 * v).norm() > 0.0) {
        EXPECT_NEAR(flat.mesh.vertices(v, 2), 0.5, 1e-12);
      }
  }
  EXPECT_THROW(finest_level_loads(
                   tree, {box_load(Vector3d(5, 5, 5), Vector3d(6, 6, 6), Vector3d::UnitX())}, 1e-9),
               InputError);
}

TEST(FinestBoundaryPoints, AreTheBoundaryVerticesOfTheFullResolutionMesh) {
  // A 2 × 1 × 1-cell box, 2 levels: the points are the boundary vertices of the level-2 mesh,
  // each once, each in (on the boundary of) its root.
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.5, 0.25), {2, 1, 1});
  TetTree tree(coarse, 2);
  const std::vector<RootPoint> points = finest_boundary_points(tree);
  const TetMesh full = flatten_cut(ActiveCut::uniform(tree, 2)).flat.mesh;
  std::vector<char> on_boundary(full.vertices.rows(), 0);
  const MatrixX3i faces = boundary_faces(full.tets);
  for (Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      on_boundary[faces(f, k)] = 1;
  std::vector<int> matches(points.size(), 0);
  Index boundary_vertices = 0;
  for (Index v = 0; v < full.vertices.rows(); ++v) {
    if (!on_boundary[v]) continue;
    ++boundary_vertices;
    int found = 0;
    for (size_t p = 0; p < points.size(); ++p)
      if ((points[p].position - full.vertices.row(v).transpose()).norm() < 1e-12) {
        ++found;
        ++matches[p];
      }
    EXPECT_EQ(found, 1) << "boundary vertex " << v;
  }
  EXPECT_EQ(static_cast<Index>(points.size()), boundary_vertices);
  // A closed surface of F triangles (16 per coarse boundary triangle) has 2 + F / 2 vertices.
  EXPECT_EQ(static_cast<Index>(points.size()), 2 + 16 * boundary_faces(coarse.tets).rows() / 2);
  for (size_t p = 0; p < points.size(); ++p) {
    EXPECT_EQ(matches[p], 1);
    const Matrix3x4d x = tree.tet_positions(points[p].root);
    const Eigen::Vector4d lambda =
        tet_barycentric_coordinates(points[p].position, x.col(0), x.col(1), x.col(2), x.col(3));
    EXPECT_GE(lambda.minCoeff(), -1e-12);
    EXPECT_LE(lambda.minCoeff(), 1e-12);  // on a face of the root
  }
}

TEST(AdaptiveSimulation, SmallFixedPatchIsResolvedExactly) {
  // A prescribed patch on the top face that contains no coarse vertex: the driver refines until
  // every finest vertex in the patch is interpolated from selected vertices only, so all of them
  // move exactly as prescribed.
  const TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.5), {2, 2, 1});
  std::vector<DirichletSpec> groups = {fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitZ())};
  DirichletSpec push;
  push.name = "prescribed.0";
  push.region = BoxRegion{Vector3d(0.125, 0.125, 0.5), Vector3d(0.375, 0.375, 0.5)};
  push.kind = DirichletKind::displacement;
  push.displacement = Vector3d(0, 0, -0.01);
  groups.push_back(push);
  AdaptiveSimulation sim(coarse, hierarchy(3, HierarchyMode::uniform, 0),
                         {.material = rubber(), .dirichlet = groups}, static_settings(1));
  EXPECT_GT(sim.cut().size(), coarse.tets.rows());            // refined for exactness
  EXPECT_LT(sim.cut().size(), 512 * coarse.tets.rows() / 4);  // … only near the patch
  run(sim);
  const FlatTreeMesh& flat = sim.flat();
  const VectorXd& x = sim.simulation().positions();
  int in_patch = 0;
  for (Index v = 0; v < flat.mesh.vertices.rows(); ++v) {
    const Vector3d X = flat.mesh.vertices.row(v).transpose();
    if (X.z() == 0.5 && X.x() >= 0.125 && X.x() <= 0.375 && X.y() >= 0.125 && X.y() <= 0.375) {
      ++in_patch;
      EXPECT_LT((x.segment<3>(3 * v) - X - push.displacement).norm(), 1e-12);
    }
  }
  EXPECT_GE(in_patch, 9);
  // Finest-level material points inside the patch follow it too (probes between vertices).
  MatrixX3d probes(2, 3);
  probes << 0.2, 0.3, 0.5, 0.37, 0.13, 0.5;
  const MatrixX3d u = sim.displacements(sim.locate(probes, "probes", 1e-9));
  for (Index i = 0; i < 2; ++i)
    EXPECT_LT((u.row(i).transpose() - push.displacement).norm(), 1e-12);
}

/// A slab fixed at the bottom, pressed by a small patch on top.
struct PressedSlab {
  TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.25), {4, 4, 1});
  std::vector<DirichletSpec> fixed = {fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitZ())};
  std::vector<RegionLoad> loads = {
      box_load(Vector3d(0.4, 0.4, 0.25), Vector3d(0.6, 0.6, 0.25), Vector3d(0, 0, -500.0))};
  MatrixX3d probe = (MatrixX3d(1, 3) << 0.5, 0.5, 0.25).finished();

  ProblemSpec problem() const { return {.material = rubber(), .dirichlet = fixed, .loads = loads}; }
  /// The symplectic-Euler stable-step estimate of the finest level of `levels`.
  double finest_explicit_dt(int levels) const {
    SolverSettings settings;
    settings.integrator = Integrator::symplectic_euler;
    return AdaptiveSimulation(coarse, hierarchy(levels, HierarchyMode::full), problem(), settings)
        .simulation()
        .stable_dt_estimate();
  }

  double probe_uz(const HierarchySettings& settings, Index* tets) const {
    AdaptiveSimulation sim(coarse, settings,
                           {.material = rubber(), .dirichlet = fixed, .loads = loads},
                           static_settings(2));
    run(sim);
    if (tets) *tets = sim.cut().size();
    return sim.displacements(sim.locate(probe, "probes", 1e-9))(0, 2);
  }
};

TEST(AdaptiveSimulation, LocalisedLoadRefinesNearItAndApproachesFullResolution) {
  const PressedSlab slab;
  Index full_tets = 0, coarse_tets = 0, adaptive_tets = 0;
  const double full = slab.probe_uz(hierarchy(2, HierarchyMode::full), &full_tets);
  const double coarse = slab.probe_uz(hierarchy(2, HierarchyMode::uniform, 0), &coarse_tets);
  const double adaptive = slab.probe_uz(hierarchy(2, HierarchyMode::adaptive, 0), &adaptive_tets);
  ASSERT_LT(full, 0.0);
  const double coarse_error = std::abs(coarse - full) / std::abs(full);
  const double adaptive_error = std::abs(adaptive - full) / std::abs(full);
  EXPECT_GT(coarse_error, 0.05);  // the coarse mesh is far off: the scene needs refinement
  EXPECT_LT(adaptive_error, 0.25 * coarse_error);
  EXPECT_LT(adaptive_tets, full_tets / 2);
  EXPECT_GT(adaptive_tets, coarse_tets);
}

/// Backward Euler on the pressed slab for 20 steps of 2 ms, adapting every 2 steps from
/// `start_level` of 2 levels.
struct ChangingSlabRun {
  SolverSettings solver;
  HierarchySettings hierarchy;
};
ChangingSlabRun changing_slab_run(
    int start_level, LinearSolverKind linear_solver = SolverSettings().newton.linear_solver) {
  ChangingSlabRun run;
  run.solver.integrator = Integrator::implicit_euler;
  run.solver.newton.linear_solver = linear_solver;
  run.solver.dt = 2e-3;
  run.solver.duration = 0.04;
  run.hierarchy = hierarchy(2, HierarchyMode::adaptive, start_level);
  run.hierarchy.adapt_every = 2;
  run.hierarchy.criteria.min_steps_between_changes = 2;
  return run;
}

TEST(AdaptiveSimulation, RefinementKeepsTheEnergyAndTheCutFollowsTheLoad) {
  const PressedSlab slab;
  const ChangingSlabRun setup = changing_slab_run(0);
  AdaptiveSimulation sim(slab.coarse, setup.hierarchy,
                         {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
                         setup.solver);
  run(sim);
  ASSERT_FALSE(sim.changes().empty());
  for (const CutChangeRecord& change : sim.changes()) {
    // The parts of a change's time are non-negative, add up to it, and the rebuild has them all.
    const CutChangePhases& p = change.phases;
    const std::array<double, 8> parts = {p.edit,    p.flatten, p.elastic_model, p.reduced_model,
                                         p.problem, p.stepper, p.transfer,      p.records};
    double sum = 0.0;
    for (const double part : parts) {
      EXPECT_GE(part, 0.0);
      sum += part;
    }
    EXPECT_GT(change.seconds, 0.0);
    EXPECT_NEAR(sum, change.seconds, 1e-9);
    EXPECT_GT(p.flatten, 0.0);
    EXPECT_GT(p.elastic_model, 0.0);
    EXPECT_GT(p.reduced_model, 0.0);
    EXPECT_GT(p.stepper, 0.0);
    // No prescribed vertex moves here (fixed bottom), so the transfer keeps the momentum of the
    // free vertices exactly (the fixed ones have zero velocity on every cut).
    EXPECT_LT((change.momentum_after - change.momentum_before).norm(),
              1e-9 * std::max(1e-12, change.momentum_before.norm()));
  }
  // A steady load: no node flickers (refined and merged back repeatedly).
  for (NodeId n = 0; n < sim.tree().pool_size(); ++n)
    EXPECT_LE(sim.controller().change_count(n), 2) << "node " << n;
  for (const CutChangeRecord& change : sim.changes())
    if (change.coarsened == 0) {
      // New vertices lie on the old linear field: same positions and velocities, same energy.
      EXPECT_NEAR(change.energy_after, change.energy_before,
                  1e-9 * std::max(1e-12, change.energy_before));
    }
  // Every refined tet lies near the patch (within one coarse cell of it).
  const VectorXi levels = sim.cell_levels();
  const FlatTreeMesh& flat = sim.flat();
  for (Index t = 0; t < levels.size(); ++t)
    if (levels[t] > 0) {
      Vector3d centroid = Vector3d::Zero();
      for (int k = 0; k < 4; ++k)
        centroid += flat.mesh.vertices.row(flat.mesh.tets(t, k)).transpose() / 4.0;
      EXPECT_LT((centroid.head<2>() - Eigen::Vector2d(0.5, 0.5)).lpNorm<Eigen::Infinity>(), 0.4);
    }
  EXPECT_EQ(sim.history().size(), static_cast<size_t>(sim.step_count() + 1));
}

TEST(AdaptiveSimulation, ACutChangeRecordsTheMultigridSetupsOfItsCut) {
  // The solve after a change builds the multigrid hierarchy of the new cut: each change's record
  // holds the setups made on its cut, all of the run's but those on the initial cut. CHOLMOD
  // builds none. Where the new cut's coarse spaces are those of the cut before, the setup keeps
  // the coarse levels and sets up only the finest: here at every change, since every cut holds
  // the whole slab at level 1 or finer, so the coarse spaces (the vertices of levels ≤ 1, none of
  // them hanging) do not change. The run still reaches the states CHOLMOD's run reaches.
  const PressedSlab slab;
  std::vector<VectorXd> final_positions;
  std::vector<std::vector<Index>> cut_sizes;
  for (const LinearSolverKind solver : {LinearSolverKind::multigrid, LinearSolverKind::cholmod}) {
    // From level 1: the cuts have a coarse level of an eighth of their vertices (a space that
    // shrinks less is merged into the next, and a single level is solved by CHOLMOD).
    const ChangingSlabRun setup = changing_slab_run(1, solver);
    AdaptiveSimulation sim(slab.coarse, setup.hierarchy,
                           {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
                           setup.solver);
    run(sim);
    ASSERT_GE(sim.changes().size(), 2u);
    long recorded = 0, carried = 0;
    std::vector<Index>& sizes = cut_sizes.emplace_back();
    for (const CutChangeRecord& change : sim.changes()) {
      sizes.push_back(change.tets_after);
      recorded += change.multigrid_setups;
      carried += change.multigrid_carried_setups;
      EXPECT_LE(change.multigrid_carried_setups, change.multigrid_setups);
      if (solver == LinearSolverKind::cholmod) {
        EXPECT_EQ(change.multigrid_setups, 0);
        EXPECT_EQ(change.multigrid_setup_seconds, 0.0);
        continue;
      }
      // Every change here is followed by a step on its cut (the last comes before the end).
      EXPECT_GE(change.multigrid_setups, 1) << "change after step " << change.step;
      EXPECT_GT(change.multigrid_setup_seconds, 0.0);
    }
    const SimulationCounters counters = sim.counters();
    if (solver == LinearSolverKind::multigrid) {
      // The initial cut's (at least its first solve) are the ones no change holds.
      EXPECT_GE(counters.multigrid_setups - recorded, 1);
      EXPECT_LE(recorded, counters.multigrid_setups);
      EXPECT_EQ(carried, static_cast<long>(sim.changes().size()));
      EXPECT_EQ(counters.multigrid_carried_setups, carried);
      RecordProperty("carried setups", std::to_string(carried) + " of " + std::to_string(recorded) +
                                           " after cut changes");
    } else {
      EXPECT_EQ(counters.multigrid_setups, 0);
      EXPECT_EQ(carried, 0);
    }
    final_positions.push_back(sim.simulation().positions() -
                              flatten(sim.simulation().mesh().vertices));
  }
  ASSERT_EQ(cut_sizes[0], cut_sizes[1]);  // the same cuts, so the same final mesh
  const double scale = final_positions[1].lpNorm<Eigen::Infinity>();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE((final_positions[0] - final_positions[1]).lpNorm<Eigen::Infinity>(), 1e-7 * scale);
}

TEST(AdaptiveSimulation, ACutChangeSeedsTheNewCutsSmoothersWithThoseOfTheCutBefore) {
  // The first multigrid setup on a new cut takes the smoothers' Lanczos estimates of the cut the
  // change left, level by level where the level's size stays within a factor 2
  // (MultigridPreconditioner::seed_smoother_estimates).
  const PressedSlab slab;
  const ChangingSlabRun setup = changing_slab_run(1, LinearSolverKind::multigrid);
  AdaptiveSimulation sim(slab.coarse, setup.hierarchy,
                         {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
                         setup.solver);
  std::vector<SmootherEstimate> left;  // of the cut a change left, until the new cut's first setup
  int compared_levels = 0;
  while (!sim.finished()) {
    const std::vector<SmootherEstimate> before = sim.current().smoother_estimates();
    const std::size_t changes = sim.changes().size();
    const long setups_before = sim.counters().multigrid_setups;
    sim.advance();
    if (sim.changes().size() == changes + 1) {
      // The estimates taken before the step are those the change passed on unless the step set
      // up the old cut's multigrid again.
      const long on_old_cut = sim.counters().multigrid_setups - setups_before -
                              sim.current().counters().multigrid_setups;
      left = on_old_cut == 0 ? before : std::vector<SmootherEstimate>{};
    } else if (sim.changes().size() > changes + 1) {
      left.clear();  // several changes in one step: the cut between them is not observed
    }
    if (left.empty()) continue;
    const long setups = sim.current().counters().multigrid_setups;
    if (setups == 0) continue;  // no solve on the new cut yet
    if (setups == 1) {
      const std::vector<SmootherEstimate> now = sim.current().smoother_estimates();
      if (now.size() == left.size()) {
        for (std::size_t k = 0; k < now.size(); ++k) {
          if (2 * left[k].rows < now[k].rows || left[k].rows > 2 * now[k].rows) continue;
          EXPECT_EQ(now[k].lambda, left[k].lambda)
              << "level " << k + 1 << " after step " << sim.changes().back().step;
          ++compared_levels;
        }
      }
    }
    left.clear();
  }
  ASSERT_GE(sim.changes().size(), 2u);
  EXPECT_GE(compared_levels, 1);
}

TEST(AdaptiveSimulation, ExplicitIntegratorNeverRefinesBelowItsStableStep) {
  const PressedSlab slab;
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.duration = 0.0;
  // dt between the coarse and the level-1 stable step: refinement must be refused.
  settings.dt = 1.0;
  settings.duration = 1.0;
  const double coarse_dt =
      Simulation(slab.coarse, {.material = rubber()}, settings).stable_dt_estimate();
  settings.dt = 0.9 * coarse_dt;
  settings.duration = 20 * settings.dt;
  HierarchySettings h = hierarchy(2, HierarchyMode::adaptive, 0);
  h.adapt_every = 1;
  h.criteria.min_steps_between_changes = 0;
  AdaptiveSimulation sim(slab.coarse, h,
                         {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
                         settings);
  run(sim);
  EXPECT_EQ(sim.cut().finest_level(), 0);
  // The error-controlled defaults: over the tolerance on a cut no tet of which may refine, the
  // controller is not asked at all; each such decision is counted.
  HierarchySettings defaults;
  defaults.levels = 2;
  AdaptiveSimulation controlled(
      slab.coarse, defaults, {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
      settings);
  run(controlled);
  EXPECT_EQ(controlled.cut().finest_level(), 0);
  const ToleranceReport& report = controlled.tolerance_report();
  EXPECT_GT(report.steps_over_tolerance, 0);
  EXPECT_EQ(report.steps_unrefinable, report.steps_over_tolerance);
  // Only the initial adaptation's one decision refused (each root once), none of the steps'.
  EXPECT_LE(report.refused_refinements, slab.coarse.tets.rows());
  // With a small enough step the same scene refines.
  settings.dt = 0.2 * coarse_dt;
  settings.duration = 20 * settings.dt;
  AdaptiveSimulation fine(slab.coarse, h,
                          {.material = rubber(), .dirichlet = slab.fixed, .loads = slab.loads},
                          settings);
  run(fine);
  EXPECT_GT(fine.cut().finest_level(), 0);
}

TEST(AdaptiveSimulation, ExplicitRunsGoOnAtFullResolutionOnlyWhereTheFinestLevelIsStable) {
  // Any refinement takes the slab's cut past a fraction of 0.02 of the finest level.
  const PressedSlab slab;
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  const double finest_dt = slab.finest_explicit_dt(2);
  HierarchySettings h = hierarchy(2, HierarchyMode::adaptive, 0);
  h.adapt_every = 1;
  h.criteria.min_steps_between_changes = 0;
  h.full_resolution_fraction = 0.02;
  const auto run_at = [&](double dt) {
    settings.dt = dt;
    settings.duration = 20 * dt;
    auto sim = std::make_unique<AdaptiveSimulation>(slab.coarse, h, slab.problem(), settings);
    run(*sim);
    return sim;
  };
  // Within the finest level's stable step: the first refinement goes on at full resolution.
  const auto stable = run_at(0.5 * finest_dt);
  EXPECT_GE(stable->tolerance_report().full_resolution_step, 0);
  EXPECT_EQ(stable->cut().size(), slab.coarse.tets.rows() * 64);
  // Beyond it (within level 1's, about twice as long): refined only where the children stay
  // stable, and never at full resolution.
  const auto unstable = run_at(1.3 * finest_dt);
  EXPECT_EQ(unstable->tolerance_report().full_resolution_step, -1);
  EXPECT_GE(unstable->cut().finest_level(), 1);
  EXPECT_LT(unstable->cut().size(), slab.coarse.tets.rows() * 64);
  EXPECT_GT(unstable->tolerance_report().refused_refinements, 0);
}

TEST(AdaptiveSimulation, ExplicitRunsTakeTheStableStepOfSiblingGroups) {
  // The veto and the full-resolution switch bound the finest level's highest frequency over groups
  // of eight siblings (stable_time_step.hpp), tighter than the element bound: a dt between the
  // two refines to the finest level and stays stable there.
  const PressedSlab slab;
  const ProblemSpec problem = slab.problem();
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  const AdaptiveSimulation full(slab.coarse, hierarchy(2, HierarchyMode::full), problem, settings);
  const TetMesh& finest = full.simulation().mesh();
  const double element_dt = stable_time_step_estimate(finest.vertices, finest.tets, rubber(),
                                                      Integrator::symplectic_euler);
  const double group_dt = full.simulation().stable_dt_estimate();
  EXPECT_GT(group_dt, 1.3 * element_dt);
  // The same bound from every sibling group's own eigen-solve (the run keeps them by shape).
  std::vector<int> parents(full.flat().tet_nodes.size());
  for (std::size_t t = 0; t < parents.size(); ++t)
    parents[t] = full.tree().parent(full.flat().tet_nodes[t]);
  const double direct_dt = stable_time_step_estimate(finest.vertices, finest.tets, rubber(),
                                                     Integrator::symplectic_euler, parents);
  EXPECT_NEAR(group_dt, direct_dt, 1e-8 * direct_dt);
  std::printf("finest level's stable step: groups of siblings %.4g s, tets alone %.4g s (%.3f)\n",
              group_dt, element_dt, group_dt / element_dt);

  settings.dt = std::sqrt(element_dt * group_dt);
  settings.duration = 40 * settings.dt;
  HierarchySettings h = hierarchy(2, HierarchyMode::adaptive, 0);
  h.adapt_every = 1;
  h.criteria.min_steps_between_changes = 0;
  h.full_resolution_fraction = 0.02;
  AdaptiveSimulation sim(slab.coarse, h, problem, settings);
  run(sim);
  EXPECT_GE(sim.tolerance_report().full_resolution_step, 0);
  EXPECT_EQ(sim.cut().size(), finest.tets.rows());
  EXPECT_EQ(sim.tolerance_report().refused_refinements, 0);
  EXPECT_GE(sim.simulation().stable_dt_estimate(), settings.dt);
  // The full-resolution run at that step: 400 steps, no divergence, and the energy within what
  // the load's work can make it: an undamped oscillator under a step load swings to twice its
  // static displacement, where kinetic and elastic energy add up to 4 times the static response's
  // elastic energy (the margin: symplectic Euler's energy error and the material's nonlinearity).
  SolverSettings long_run = settings;
  long_run.duration = 400 * settings.dt;
  AdaptiveSimulation held(slab.coarse, hierarchy(2, HierarchyMode::full), problem, long_run);
  double largest_energy = 0.0;
  while (!held.finished()) {
    ASSERT_NO_THROW(held.advance());
    largest_energy = std::max(
        largest_energy, held.simulation().kinetic_energy() + held.simulation().elastic_energy());
  }
  AdaptiveSimulation statics(slab.coarse, hierarchy(2, HierarchyMode::full), problem,
                             static_settings(1));
  run(statics);
  EXPECT_LT(largest_energy, 4.5 * statics.simulation().elastic_energy());
}

TEST(AdaptiveSimulation, ExplicitRunsGoOnAtFullResolutionWhereAnAdaptiveStepCostsMore) {
  // An explicit step costs f force evaluations per tet (1 symplectic Euler, 4 RK4), an adaptive
  // step also the decision's estimate, about kExplicitEstimateCost of them: past f / (f + cost) of
  // the finest level's tets full resolution is cheaper.
  const PressedSlab slab;
  const ProblemSpec problem = slab.problem();
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.dt = 0.5 * slab.finest_explicit_dt(2);
  settings.duration = 10 * settings.dt;
  const double cost = AdaptiveSimulation::kExplicitEstimateCost;
  HierarchySettings h;
  h.levels = 2;
  h.tolerance = 0.05;
  const auto fraction = [&](Integrator integrator, double set) {
    SolverSettings s = settings;
    s.integrator = integrator;
    HierarchySettings with = h;
    with.full_resolution_fraction = set;
    return AdaptiveSimulation(slab.coarse, with, problem, s).full_resolution_fraction();
  };
  EXPECT_DOUBLE_EQ(fraction(Integrator::symplectic_euler, 0.75), 1.0 / (1.0 + cost));
  EXPECT_DOUBLE_EQ(fraction(Integrator::rk4, 0.75), 4.0 / (4.0 + cost));
  EXPECT_DOUBLE_EQ(fraction(Integrator::symplectic_euler, 0.05), 0.05);
  EXPECT_DOUBLE_EQ(fraction(Integrator::symplectic_euler, 1.0), 1.0);  // never
  EXPECT_DOUBLE_EQ(fraction(Integrator::implicit_euler, 0.75), 0.75);
  // The slab's first cut lies between the explicit share and the default 0.75: never sent to full
  // resolution it stays adaptive, by default it goes on at full resolution before its first step.
  const Index finest = slab.coarse.tets.rows() * 64;
  h.full_resolution_fraction = 1.0;
  AdaptiveSimulation kept(slab.coarse, h, problem, settings);
  const double share = static_cast<double>(kept.cut().size()) / static_cast<double>(finest);
  ASSERT_GT(share, 1.0 / (1.0 + cost));
  ASSERT_LT(share, 0.75);
  h.full_resolution_fraction = 0.75;
  AdaptiveSimulation sim(slab.coarse, h, problem, settings);
  EXPECT_EQ(sim.tolerance_report().full_resolution_step, 0);
  EXPECT_EQ(sim.cut().size(), finest);
  run(sim);
  // Backward Euler keeps the same first cut adaptive.
  SolverSettings implicit = settings;
  implicit.integrator = Integrator::implicit_euler;
  const AdaptiveSimulation implicit_run(slab.coarse, h, problem, implicit);
  EXPECT_EQ(implicit_run.tolerance_report().full_resolution_step, -1);
  EXPECT_LT(implicit_run.cut().size(), finest);
}

TEST(AdaptiveSimulation, RejectsBadSettings) {
  const Bar bar;
  HierarchySettings h = hierarchy(2, HierarchyMode::uniform, 3);
  EXPECT_THROW(AdaptiveSimulation(bar.coarse, h,
                                  {.material = rubber(),
                                   .dirichlet = bar.fixed,
                                   .loads = bar.loads,
                                   .gravity = bar.gravity},
                                  static_settings(1)),
               InputError);
  h = hierarchy(9, HierarchyMode::full);
  EXPECT_THROW(validate_hierarchy_settings(h, "hierarchy"), InputError);
  h = hierarchy(2, HierarchyMode::adaptive);
  h.indicator = "magic";
  EXPECT_THROW(validate_hierarchy_settings(h, "hierarchy"), InputError);
}

}  // namespace
}  // namespace strata
