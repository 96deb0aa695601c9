// Obstacles on the hierarchy (AdaptiveSimulation, "Contact"): full mode against core on the
// leaves with the same barrier, a block dropped on a sphere on an adaptive cut stays within the
// tolerance, fine contact points embedded in a coarse cut carry the body where its vertices do
// not touch, a sphere sliding over a clamped slab is refined under and released behind, the
// push-out of a transferred state, and a cut change that fails (the refined cut's rest state is
// inside an obstacle) leaving the previous cut at the start of the step.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>

#include "adaptive_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"

namespace strata {
namespace {

using testing::hierarchy;
using testing::rubber;

Obstacle sphere_obstacle(const Vector3d& center, double radius) {
  Obstacle obstacle;
  obstacle.name = "sphere";
  obstacle.distance = [center, radius](const Vector3d& p, Vector3d& gradient) {
    const Vector3d r = p - center;
    gradient = r.normalized();
    return r.norm() - radius;
  };
  return obstacle;
}

/// Error-controlled adaptive settings (recovery estimate, in-step refinement) at `tolerance`; the
/// cut adapts however large it grows (no switch to full resolution), as these tests follow it.
HierarchySettings error_controlled(int levels, double tolerance) {
  HierarchySettings settings;
  settings.levels = levels;
  settings.mode = HierarchyMode::adaptive;
  settings.tolerance = tolerance;
  settings.full_resolution_fraction = 1.0;
  return settings;
}

TEST(AdaptiveContact, FullModeEqualsCoreOnTheLeavesWithTheSameBarrier) {
  const TetMesh coarse =
      box_tet_mesh(Vector3d(-0.05, -0.05, 0.22), Vector3d(0.05, 0.05, 0.32), {1, 1, 1});
  const std::vector<Obstacle> obstacles = {sphere_obstacle(Vector3d::Zero(), 0.2)};
  SolverSettings settings;
  settings.dt = 2e-3;
  settings.duration = 0.16;
  const Vector3d gravity(0, 0, -9.81);
  AdaptiveSimulation full(coarse, hierarchy(1, HierarchyMode::full),
                          {.material = rubber(), .gravity = gravity, .obstacles = obstacles},
                          settings);
  SimulationOptions options;
  options.contact_stiffness = full.contact_stiffness();
  Simulation leaves(full.flat().mesh,
                    {.material = rubber(), .gravity = gravity, .obstacles = obstacles}, settings,
                    std::move(options));
  while (!leaves.finished()) {
    full.advance();
    leaves.advance();
  }
  EXPECT_GT(leaves.max_penetration(), 0.0);  // it landed
  const double scale = (leaves.positions() - leaves.model().rest_positions()).norm();
  EXPECT_LE((full.simulation().positions() - leaves.positions()).norm(), 1e-9 * scale);
  EXPECT_NEAR(full.max_penetration(), leaves.max_penetration(), 1e-9 * 0.2);
  ASSERT_EQ(full.contact_counts().size(), leaves.contact_counts().size());
  EXPECT_EQ(full.contact_counts(), leaves.contact_counts());
}

TEST(AdaptiveContact, BlockDroppedOnASphereStaysWithinTheToleranceOnAnAdaptiveCut) {
  const TetMesh coarse =
      box_tet_mesh(Vector3d(-0.05, -0.05, 0.22), Vector3d(0.05, 0.05, 0.32), {2, 2, 2});
  SolverSettings settings;
  settings.dt = 2e-3;
  settings.duration = 0.3;
  AdaptiveSimulation sim(coarse, error_controlled(1, 0.01),
                         {.material = rubber(),
                          .gravity = Vector3d(0, 0, -9.81),
                          .obstacles = {sphere_obstacle(Vector3d::Zero(), 0.2)}},
                         settings);
  double lowest = 1.0;
  while (!sim.finished()) {
    sim.advance();
    const VectorXd& x = sim.simulation().positions();
    for (Index v = 0; v < x.size() / 3; ++v)
      lowest = std::min(lowest, x.segment<3>(3 * v).norm() - 0.2);
  }
  const double tolerance = sim.simulation().contact_settings().distance;
  EXPECT_GT(sim.max_penetration(), 0.0);  // it landed
  EXPECT_LE(sim.max_penetration(), tolerance);
  EXPECT_GE(lowest, -tolerance);
  EXPECT_GT(*std::max_element(sim.contact_counts().begin(), sim.contact_counts().end()), 0);
  EXPECT_EQ(static_cast<long>(sim.contact_counts().size()), sim.step_count());
  EXPECT_GT(sim.changes().size(), 0u);  // the impact refined the cut
  for (const CutChangeRecord& change : sim.changes())
    EXPECT_LE(change.contact_correction, 0.1);  // a push-out is a small correction, if any
}

TEST(AdaptiveContact, AFailedCutChangeLeavesThePreviousCutAtTheStartOfTheStep) {
  // A block clamped at its top, whose bottom face a sphere pokes through between the corners,
  // with only each cut's boundary vertices as contact points: the coarse cut is feasible, but
  // refinement puts the face's centre (a new vertex) inside the sphere, and the Simulation of the
  // refined cut refuses that rest state. The first step's redo on the refined cut therefore
  // fails. (With the finest level's boundary points, the default, the scene is refused at the
  // start: the face's centre is one of them.)
  const TetMesh coarse =
      box_tet_mesh(Vector3d(-0.05, -0.05, 0.22), Vector3d(0.05, 0.05, 0.32), {1, 1, 1});
  HierarchySettings settings = error_controlled(1, 1e-6);
  settings.initial_adaptation = false;
  settings.finest_contact_points = false;
  SolverSettings solver;
  solver.dt = 2e-3;
  solver.duration = 0.02;
  const std::vector<DirichletSpec> clamp = {
      testing::fixed_plane("top", Vector3d(0, 0, 0.32), Vector3d::UnitZ())};
  AdaptiveSimulation sim(coarse, settings,
                         {.material = rubber(),
                          .dirichlet = clamp,
                          .gravity = Vector3d(0, 0, -9.81),
                          .obstacles = {sphere_obstacle(Vector3d::Zero(), 0.223)}},
                         solver);
  const Index root_tets = sim.cut().size();
  const VectorXd start = sim.simulation().positions();
  try {
    sim.advance();
    ADD_FAILURE() << "the step on the refined cut did not fail";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("inside the obstacle"), std::string::npos)
        << error.what();
  }
  // The previous cut, with a Simulation at the start of the step that failed.
  EXPECT_EQ(sim.cut().size(), root_tets);
  EXPECT_EQ(sim.simulation().mesh().tets.rows(), root_tets);
  EXPECT_EQ(sim.step_count(), 0);
  EXPECT_EQ(sim.simulation().positions(), start);
  EXPECT_TRUE(sim.changes().empty());
  EXPECT_THROW(sim.advance(), std::logic_error);
}

TEST(AdaptiveContact, ASphereBetweenTheCoarseVerticesIsFeltOnACoarseCut) {
  // A block dropped onto the top of a sphere that meets its bottom face at the face's centre, 3 cm
  // from the nearest coarse vertex, on the coarse cut of a 2-level tree (uniform level 0, so the
  // cut stays coarse). With the finest level's boundary points as contact points the face's
  // centre stops at the sphere; with the coarse cut's boundary vertices alone the sphere passes
  // between them and pokes into the face.
  const TetMesh coarse =
      box_tet_mesh(Vector3d(-0.05, -0.05, 0.22), Vector3d(0.05, 0.05, 0.32), {1, 1, 1});
  SolverSettings settings;
  settings.dt = 2e-3;
  settings.duration = 0.2;
  Material material = rubber();
  material.mass_damping = 20.0;
  const RootPoint centre{0, Vector3d(0, 0, 0.22)};
  const auto depth_of_centre = [&](bool finest) {
    HierarchySettings h = hierarchy(2, HierarchyMode::uniform, 0);
    h.finest_contact_points = finest;
    AdaptiveSimulation sim(coarse, h,
                           {.material = material,
                            .gravity = Vector3d(0, 0, -9.81),
                            .obstacles = {sphere_obstacle(Vector3d::Zero(), 0.2)}},
                           settings);
    TetLocator locator(coarse.vertices, coarse.tets);
    const std::optional<TetLocation> root = locator.locate(centre.position, 1e-9);
    EXPECT_TRUE(root.has_value());
    const RootPoint point{static_cast<NodeId>(root->tet), centre.position};
    double deepest = 0.0;
    while (!sim.finished()) {
      sim.advance();
      const Vector3d x = point.position + sim.displacements({point}).row(0).transpose();
      deepest = std::max(deepest, 0.2 - x.norm());
    }
    EXPECT_EQ(sim.cut().size(), coarse.tets.rows());
    return std::pair{deepest, sim.simulation().contact_settings().distance};
  };
  const auto [finest_depth, tolerance] = depth_of_centre(true);
  const auto [vertex_depth, unused] = depth_of_centre(false);
  EXPECT_LE(finest_depth, tolerance);
  EXPECT_GT(vertex_depth, 0.005);
}

TEST(AdaptiveContact, FineContactPointsCarryABlockOnACoarseCut) {
  // A block 5 cm above a plane, on the coarse cut of a 2-level tree. Material points 5 cm below
  // its bottom (outside the mesh, as a bound fine surface's vertices can be) are embedded in the
  // bottom roots and touch the plane: they, not the mesh vertices, hold the block up, and their
  // forces reach the DOFs through their weights.
  const TetMesh coarse = box_tet_mesh(Vector3d(0, 0, 0.05), Vector3d(0.1, 0.1, 0.15), {1, 1, 1});
  const TetLocator locator(coarse.vertices, coarse.tets);
  std::vector<RootPoint> surface;
  for (double x : {0.02, 0.05, 0.08})
    for (double y : {0.02, 0.05, 0.08}) {
      const Vector3d inside(x, y, 0.051);  // the root holding the point just above it
      const std::optional<TetLocation> root = locator.locate(inside, 1e-9);
      ASSERT_TRUE(root.has_value());
      surface.push_back({static_cast<NodeId>(root->tet), Vector3d(x, y, 0.0)});
    }
  SolverSettings settings;
  settings.dt = 5e-3;
  settings.duration = 0.6;
  Material material = rubber();
  material.mass_damping = 20.0;
  const Vector3d gravity(0, 0, -9.81);
  AdaptiveSimulation sim(
      coarse, hierarchy(2, HierarchyMode::uniform, 0),
      {.material = material,
       .gravity = gravity,
       .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
      settings, surface);
  while (!sim.finished())
    sim.advance();
  const Simulation& current = sim.simulation();
  EXPECT_EQ(current.extra_contact_points(), 9);
  const double tolerance = current.contact_settings().distance;
  EXPECT_GT(sim.max_penetration(), 0.0);
  EXPECT_LE(sim.max_penetration(), tolerance);
  // The mesh vertices stay about 5 cm above the plane.
  const VectorXd& x = current.positions();
  double lowest_vertex = 1.0;
  for (Index v = 0; v < x.size() / 3; ++v)
    lowest_vertex = std::min(lowest_vertex, x[3 * v + 2]);
  EXPECT_GT(lowest_vertex, 0.04);
  // At rest, the contact forces carry the weight.
  const VectorXd f = current.mesh_contact_forces();
  double lift = 0.0;
  for (Index v = 0; v < f.size() / 3; ++v)
    lift += f[3 * v + 2];
  const double weight = current.vertex_mass().sum() * 9.81;
  EXPECT_NEAR(lift, weight, 0.02 * weight);
}

TEST(AdaptiveContact, AnExplicitImpactIsMetOnTheFinestLevel) {
  // A block one root thick dropped 1 cm onto the ground with symplectic Euler. The projection
  // stops each contact vertex, removing the kinetic energy of its lumped mass: on the roots half
  // the block's. The tets in contact go to the finest level in the step of the impact (redone),
  // so the bounce follows full resolution's; without that the adaptive block ended 6.9 % off.
  const TetMesh coarse =
      box_tet_mesh(Vector3d(-0.1, -0.05, 0.01), Vector3d(0.1, 0.05, 0.06), {4, 2, 1});
  Material material = rubber();
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.45;
  material.mass_damping = 0.5;
  const ProblemSpec problem{
      .material = material,
      .gravity = Vector3d(0, 0, -9.81),
      .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}};
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.dt = 1e-4;
  settings.duration = 0.07;
  // Half the finest level's stable step: no refinement is refused for it.
  settings.dt =
      0.5 * AdaptiveSimulation(coarse, hierarchy(2, HierarchyMode::full), problem, settings)
                .simulation()
                .stable_dt_estimate();
  AdaptiveSimulation full(coarse, hierarchy(2, HierarchyMode::full), problem, settings);
  AdaptiveSimulation adaptive(coarse, error_controlled(2, 0.01), problem, settings);
  const MatrixX3d probes =
      (MatrixX3d(3, 3) << 0, 0, 0.01, 0.1, 0.05, 0.06, -0.1, 0, 0.035).finished();
  const std::vector<RootPoint> full_points = full.locate(probes, "probes", 1e-9);
  const std::vector<RootPoint> adaptive_points = adaptive.locate(probes, "probes", 1e-9);
  double largest = 0.0, largest_difference = 0.0;
  bool met_on_the_finest_level = false;
  while (!full.finished()) {
    full.advance();
    adaptive.advance();
    const MatrixX3d u = full.displacements(full_points);
    const MatrixX3d difference = adaptive.displacements(adaptive_points) - u;
    for (Index p = 0; p < u.rows(); ++p) {
      largest = std::max(largest, u.row(p).norm());
      largest_difference = std::max(largest_difference, difference.row(p).norm());
    }
    if (!met_on_the_finest_level && adaptive.max_penetration() > 0.0)
      met_on_the_finest_level = adaptive.cut().finest_level() == 2;
  }
  EXPECT_GT(full.max_penetration(), 0.0);  // it landed
  EXPECT_TRUE(met_on_the_finest_level);
  EXPECT_EQ(adaptive.tolerance_report().refused_refinements, 0);
  EXPECT_LT(largest_difference, 0.01 * largest);
  std::printf("explicit drop: %.3f %% off full resolution\n", 100.0 * largest_difference / largest);
}

TEST(AdaptiveContact, ASlidingSphereIsRefinedUnderAndReleasedBehind) {
  // A slab clamped at its base; a sphere comes in from the left and moves along it, indenting
  // the top by 5 mm. The cut is refined where the sphere presses and coarsened again after it has
  // passed.
  const TetMesh coarse = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.4, 0.1, 0.05), {8, 2, 1});
  const double radius = 0.05;
  Obstacle sphere = sphere_obstacle(Vector3d(-0.06, 0.05, 0.05 + radius - 0.005), radius);
  sphere.velocity = Vector3d(1.0, 0, 0);
  SolverSettings settings;
  settings.dt = 5e-3;
  settings.duration = 0.4;
  Material material = rubber();
  material.mass_damping = 50.0;
  HierarchySettings h = error_controlled(1, 0.01);
  h.criteria.min_steps_between_changes = 5;
  h.adapt_every = 5;
  AdaptiveSimulation sim(
      coarse, h,
      {.material = material,
       .dirichlet = {testing::fixed_plane("fixed", Vector3d::Zero(), Vector3d::UnitZ())},
       .obstacles = {sphere}},
      settings);
  // Mean level of the active tets with centroid x in [lo, hi].
  const auto mean_level = [&](double lo, double hi) {
    const VectorXi levels = sim.cell_levels();
    const FlatTreeMesh& flat = sim.flat();
    double sum = 0.0, count = 0.0;
    for (Index t = 0; t < flat.mesh.tets.rows(); ++t) {
      double x = 0.0;
      for (int k = 0; k < 4; ++k)
        x += 0.25 * flat.mesh.vertices(flat.mesh.tets(t, k), 0);
      if (x < lo || x > hi) continue;
      sum += levels[t];
      count += 1.0;
    }
    return count > 0.0 ? sum / count : 0.0;
  };
  double left_under = -1.0, right_under = -1.0, left_after = -1.0;
  while (!sim.finished()) {
    sim.advance();
    const double t = sim.time();
    if (std::abs(t - 0.16) < 1e-9) {  // sphere centre at x = 0.10
      left_under = mean_level(0.05, 0.15);
      right_under = mean_level(0.3, 0.4);
    }
  }
  left_after = mean_level(0.05, 0.15);      // sphere centre at x = 0.34
  EXPECT_GT(left_under, 0.5);               // refined where the sphere pressed
  EXPECT_LT(right_under, 0.1);              // not yet where it had not arrived
  EXPECT_LT(left_after, 0.5 * left_under);  // released behind it
  EXPECT_LE(sim.max_penetration(), sim.simulation().contact_settings().distance);
  Index refined = 0, coarsened = 0;
  for (const CutChangeRecord& change : sim.changes()) {
    refined += change.refined;
    coarsened += change.coarsened;
  }
  EXPECT_GT(refined, 0);
  EXPECT_GT(coarsened, 0);
}

/// A 0.1 m block on a plane (d̂ = 1 mm), continued from a state whose bottom vertices lie
/// `depth` inside the plane: the push-out tests' setting. `options` adds contact points.
struct SunkBlock {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.1, 0.1, 0.1), {1, 1, 1});

  std::unique_ptr<Simulation> sink(double depth, SimulationOptions options = {}) const {
    options.first_step = 1;  // a continued run: its state comes from set_state
    SolverSettings settings;
    settings.dt = 1e-3;
    settings.duration = 1.0;
    settings.contact.distance = 1e-3;
    auto sim = std::make_unique<Simulation>(
        mesh,
        ProblemSpec{.material = rubber(),
                    .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
        settings, std::move(options));
    VectorXd x = flatten(mesh.vertices);
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      if (x[3 * v + 2] == 0.0) x[3 * v + 2] = -depth;
    sim->set_state(x, VectorXd::Zero(x.size()));
    return sim;
  }
  /// The largest depth of a vertex inside the plane.
  double deepest(const Simulation& sim) const {
    double deepest = 0.0;
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      deepest = std::max(deepest, -sim.positions()[3 * v + 2]);
    return deepest;
  }
};

TEST(AdaptiveContact, PushOutMovesAnInfeasibleStateToTheSurface) {
  // A block whose bottom vertices are moved 3 mm into a plane (deeper than the 1 mm tolerance):
  // the push-out lifts them to the plane and leaves the others.
  const SunkBlock block;
  const std::unique_ptr<Simulation> sim = block.sink(3e-3);
  EXPECT_NEAR(sim->push_out_of_obstacles(), 3e-3, 1e-12);
  for (Index v = 0; v < block.mesh.vertices.rows(); ++v) {
    const double z = sim->positions()[3 * v + 2];
    EXPECT_GE(z, -0.5e-3);
    if (block.mesh.vertices(v, 2) > 0.0) {
      EXPECT_EQ(z, block.mesh.vertices(v, 2));
    }
  }
  EXPECT_EQ(sim->push_out_of_obstacles(), 0.0);  // feasible now
  sim->advance();                                // and the barrier accepts it
}

TEST(AdaptiveContact, APushOutOfPointsSharingVerticesDoesNotOvershoot) {
  // 25 contact points embedded in a block's bottom face (bilinear weights on its four corners,
  // as the finest level's points on a coarse face are), all 0.95 d̂ inside a plane: the push-out
  // to 0.8 d̂ moves the shared corners by about 0.15 d̂, leaving every point in contact. Summed,
  // the points' lifts moved the corners by several d̂, out of the plane.
  const SunkBlock block;
  std::array<int, 4> corner{};  // (0,0), (1,0), (0,1), (1,1) of the bottom face
  for (Index v = 0; v < block.mesh.vertices.rows(); ++v)
    if (block.mesh.vertices(v, 2) == 0.0)
      corner[(block.mesh.vertices(v, 0) > 0.0 ? 1 : 0) +
             (block.mesh.vertices(v, 1) > 0.0 ? 2 : 0)] = static_cast<int>(v);
  SimulationOptions options;
  options.boundary_contact_points = false;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) {
      const double a = i / 4.0, b = j / 4.0;
      options.contact_points.push_back({{corner[0], corner[1], corner[2], corner[3]},
                                        {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b}});
    }
  const std::unique_ptr<Simulation> sim = block.sink(0.95e-3, std::move(options));
  const double moved = sim->push_out_of_obstacles(0.9, 0.8);
  EXPECT_GT(moved, 0.1e-3);
  EXPECT_LT(moved, 0.2e-3);
  for (const int v : corner) {
    const double depth = -sim->positions()[3 * v + 2];
    EXPECT_GE(depth, 0.7e-3);
    EXPECT_LE(depth, 0.9e-3);
  }
}

TEST(AdaptiveContact, APushOutToADepthLeavesPointsInContactWhereTheyAre) {
  // The push-out a cut change makes: only points near the barrier's singularity (deeper than
  // 0.9 d̂) move, to 0.8 d̂; points at an equilibrium depth inside the obstacle stay in contact.
  // Lifting those to the surface (the default push-out) released their contact force and, with
  // friction, let them slide a step after every cut change.
  const SunkBlock block;
  std::unique_ptr<Simulation> sim = block.sink(3e-3);
  EXPECT_NEAR(sim->push_out_of_obstacles(0.9, 0.8), 2.2e-3, 1e-12);
  EXPECT_NEAR(block.deepest(*sim), 0.8e-3, 1e-12);
  sim = block.sink(0.7e-3);
  EXPECT_EQ(sim->push_out_of_obstacles(0.9, 0.8), 0.0);
  EXPECT_EQ(block.deepest(*sim), 0.7e-3);
  sim = block.sink(0.7e-3);
  EXPECT_NEAR(sim->push_out_of_obstacles(), 0.7e-3, 1e-12);  // the default: to the surface
  EXPECT_NEAR(block.deepest(*sim), 0.0, 1e-15);
}

}  // namespace
}  // namespace strata
