// Obstacle contact (energy/contact_term.hpp, obstacle.hpp): the barrier and friction against
// finite differences, and scenes against closed forms — a block pressed onto a plane carries the
// load, a block on a slope sticks below the friction angle and slides with
// a = g (sin θ − μ cos θ) above it, a block dropped on a sphere never gets deeper than the
// tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/energy/contact_term.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

Obstacle sphere_obstacle(const Vector3d& center, double radius, double friction = 0.0) {
  Obstacle obstacle;
  obstacle.name = "sphere";
  obstacle.friction = friction;
  obstacle.distance = [center, radius](const Vector3d& p, Vector3d& gradient) {
    const Vector3d r = p - center;
    gradient = r.normalized();
    return r.norm() - radius;
  };
  return obstacle;
}

TEST(ContactBarrier, DerivativesMatchFiniteDifferences) {
  std::vector<Obstacle> none;
  const ContactTerm term(none, std::vector<int>{}, {0.01, 3.0, 1e-4});
  EXPECT_EQ(term.barrier(0.01), 0.0);
  EXPECT_EQ(term.barrier_derivative(0.02), 0.0);
  for (double d : {1e-4, 1e-3, 5e-3, 9.9e-3}) {
    const double h = 1e-9;
    EXPECT_NEAR(term.barrier_derivative(d), (term.barrier(d + h) - term.barrier(d - h)) / (2 * h),
                1e-5 * std::abs(term.barrier_derivative(d)) + 1e-9);
    EXPECT_NEAR(term.barrier_second_derivative(d),
                (term.barrier_derivative(d + h) - term.barrier_derivative(d - h)) / (2 * h),
                1e-5 * term.barrier_second_derivative(d) + 1e-6);
    EXPECT_GT(term.barrier(d), 0.0);
    EXPECT_LT(term.barrier_derivative(d), 0.0);
    EXPECT_GT(term.barrier_second_derivative(d), 0.0);
  }
}

TEST(ContactTermDerivatives, GradientAndHessianOfBarrierAndFriction) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(0.2, 0.2, 0.1), {2, 2, 1});
  std::vector<Obstacle> obstacles = {
      plane_obstacle("plane", Vector3d(0, 0, 0.004), Vector3d::UnitZ()),
      sphere_obstacle(Vector3d(0.1, 0.1, 0.105 + 0.05), 0.05, 0.4)};
  obstacles[0].friction = 0.6;
  std::vector<int> vertices(mesh.vertices.rows());
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    vertices[v] = static_cast<int>(v);
  ContactTerm term(obstacles, vertices, {0.01, 50.0, 1e-3});
  const VectorXd x0 = flatten(mesh.vertices);
  term.set_step(x0, 0.0, 0.0);
  VectorXd x = x0;
  for (Index i = 0; i < x.size(); ++i)
    x[i] += 1e-3 * std::sin(3.0 * static_cast<double>(i));
  ASSERT_TRUE(std::isfinite(term.value(x)));
  VectorXd g = VectorXd::Zero(x.size());
  term.add_gradient(x, g);
  ASSERT_GT(g.norm(), 0.0);
  const double h = 1e-7;
  for (Index i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const double fd = (term.value(xp) - term.value(xm)) / (2 * h);
    EXPECT_NEAR(g[i], fd, 1e-5 * g.cwiseAbs().maxCoeff()) << i;
  }
  ElasticModel model(mesh.vertices, mesh.tets, Material{});
  SparseMatrixd H = model.stiffness_pattern();
  term.add_hessian(x, H, false);
  const Eigen::MatrixXd dense(H);
  for (Index j = 0; j < x.size(); ++j) {
    VectorXd xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    VectorXd gp = VectorXd::Zero(x.size()), gm = VectorXd::Zero(x.size());
    term.add_gradient(xp, gp);
    term.add_gradient(xm, gm);
    const VectorXd column = (gp - gm) / (2 * h);
    // The sphere's curvature term b'∇²φ is left out of the Hessian; only the plane's vertices
    // (below the sphere's reach) are compared exactly.
    if (x[j - j % 3 + 2] < 0.02) {
      EXPECT_LE((dense.col(j) - column).norm(), 1e-4 * (column.norm() + 1e-3)) << j;
    }
  }
  // Beyond the tolerance the barrier is infinite.
  VectorXd deep = x0;
  deep[2] = -0.02;
  EXPECT_TRUE(std::isinf(term.value(deep)));
}

/// A 0.1 m cube (2³ cells) standing on the plane z = 0.
TetMesh cube() {
  return box_tet_mesh(Vector3d::Zero(), Vector3d(0.1, 0.1, 0.1), {2, 2, 2});
}

Material rubber() {
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

/// φ + d̂ of `obstacle` at x.
double room(const Obstacle& obstacle, const Vector3d& x, double distance) {
  Vector3d gradient;
  return obstacle.distance(x, gradient) + distance;
}

TEST(ContactStepFilter, APointInContactSlidesAndOneMovingInStopsAtATenthOfItsRoom) {
  // The plane z = 0, d̂ = 0.01; a point 0.99 d̂ deep (room r₀ = 1e-4 m).
  const double distance = 0.01, r0 = 1e-4;
  const std::vector<Obstacle> obstacles = {
      plane_obstacle("plane", Vector3d::Zero(), Vector3d::UnitZ())};
  const ContactTerm term(obstacles, std::vector<int>{0}, {distance, 50.0, 1e-4});
  const Vector3d x(0.3, -0.2, r0 - distance);
  // Sliding along the plane (or leaving it) keeps the room: the whole step. The Lipschitz bound
  // alone, 0.9 r₀ / ‖Δx‖, would allow 1.8e-3 of it.
  EXPECT_EQ(term.max_step(x, Vector3d(0.05, 0.0, 0.0)), 1.0);
  EXPECT_EQ(term.max_step(x, Vector3d(-0.03, 0.04, 0.0)), 1.0);
  EXPECT_EQ(term.max_step(x, Vector3d(0.0, 0.0, 0.05)), 1.0);
  // Moving in, straight or while sliding, r(α) = r₀ − α Δz falls to r₀ / 10 at α = 0.9 r₀ / |Δz|.
  EXPECT_NEAR(term.max_step(x, Vector3d(0.0, 0.0, -1e-3)), 0.09, 1e-12);
  EXPECT_NEAR(term.max_step(x, Vector3d(0.05, 0.0, -1e-3)), 0.09, 1e-12);
  EXPECT_NEAR(term.max_step(x, Vector3d(0.0, 0.0, -1e-5)), 1.0, 0.0);
  // Far from the plane the step is whole unless it reaches it.
  const Vector3d above(0.0, 0.0, 0.5);
  EXPECT_EQ(term.max_step(above, Vector3d(3.0, 0.0, -0.2)), 1.0);
  EXPECT_NEAR(term.max_step(above, Vector3d(0.0, 0.0, -2.0)), 0.9 * (0.5 + distance) / 2.0, 1e-12);
}

TEST(ContactStepFilter, NoStepCrossesAThinWallOrLeavesACavity) {
  const double distance = 0.01;
  // A wall |x| < 5 d̂ (10 d̂ thick), and a point 0.2 m in front of it moving 1 m through it.
  Obstacle wall;
  wall.name = "wall";
  wall.distance = [&](const Vector3d& p, Vector3d& gradient) {
    gradient = Vector3d(p(0) < 0.0 ? -1.0 : 1.0, 0.0, 0.0);
    return std::abs(p(0)) - 5 * distance;
  };
  // Free space inside a sphere of radius 1: a point 0.99 d̂ into its wall, sliding along it.
  Obstacle cavity;
  cavity.name = "cavity";
  cavity.distance = [](const Vector3d& p, Vector3d& gradient) {
    gradient = -p.normalized();
    return 1.0 - p.norm();
  };
  const struct {
    const Obstacle* obstacle;
    Vector3d x, step;
  } cases[] = {{&wall, Vector3d(-0.2, 0.0, 0.0), Vector3d(1.0, 0.0, 2.0)},
               {&wall, Vector3d(-0.2, 0.0, 0.0), Vector3d(1.0, 3.0, 0.0)},
               {&cavity, Vector3d(0.0, 0.0, 1.0 + 0.99 * distance), Vector3d(0.1, 0.0, 0.0)},
               {&cavity, Vector3d(0.0, 0.0, 1.0 + 0.99 * distance), Vector3d(0.0, 0.3, 0.0)}};
  for (const auto& c : cases) {
    const std::vector<Obstacle> obstacles = {*c.obstacle};
    const ContactTerm term(obstacles, std::vector<int>{0}, {distance, 50.0, 1e-4});
    const double r0 = room(*c.obstacle, c.x, distance);
    const double alpha = term.max_step(c.x, c.step);
    SCOPED_TRACE(c.obstacle->name + " step " + std::to_string(c.step.norm()));
    // Not held back to the Lipschitz bound, and stopped before the room is gone: along the
    // whole path to α (sampled densely) the point stays out of the depth d̂.
    EXPECT_GT(alpha, 1.4 * 0.9 * r0 / c.step.norm());
    EXPECT_LT(alpha, 1.0);
    double least = r0;
    for (int k = 1; k <= 10000; ++k)
      least = std::min(least, room(*c.obstacle, c.x + (alpha * k / 10000.0) * c.step, distance));
    EXPECT_GT(least, 0.0);
    EXPECT_LT(room(*c.obstacle, c.x + alpha * c.step, distance), 0.5 * r0);
  }
}

TEST(ContactStepFilter, KeepsAtLeastATwentiethOfTheRoomAlongRandomStepsNearCurvedSurfaces) {
  // Points within 2 d̂ of a sphere of radius 1 (outside it) and of a spherical cavity (inside
  // it), with random steps up to 0.5 m: along the filtered path (sampled densely) no point
  // enters the depth d̂, and at its end each keeps at least a twentieth of its room. Along a
  // path past a sphere r(t) is convex, where interpolating between samples overshoots.
  const double distance = 0.01;
  const std::vector<Obstacle> obstacles = {sphere_obstacle(Vector3d::Zero(), 1.0)};
  Obstacle cavity;
  cavity.name = "cavity";
  cavity.distance = [](const Vector3d& p, Vector3d& gradient) {
    gradient = -p.normalized();
    return 1.0 - p.norm();
  };
  const std::vector<Obstacle> cavities = {cavity};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), depth(-0.99, 2.0), reach(0.0, 0.5);
  const auto direction = [&] {
    Vector3d d(unit(rng), unit(rng), unit(rng));
    return d.normalized();
  };
  int limited = 0;
  for (int i = 0; i < 400; ++i) {
    const bool inside = i % 2 == 1;
    const std::vector<Obstacle>& set = inside ? cavities : obstacles;
    const Vector3d x = (1.0 + (inside ? -1.0 : 1.0) * depth(rng) * distance) * direction();
    const Vector3d step = reach(rng) * direction();
    const ContactTerm term(set, std::vector<int>{0}, {distance, 50.0, 1e-4});
    const double r0 = room(set[0], x, distance);
    const double alpha = term.max_step(x, step);
    ASSERT_GT(alpha, 0.0);
    limited += alpha < 1.0;
    double least = r0;
    for (int k = 1; k <= 2000; ++k)
      least = std::min(least, room(set[0], x + (alpha * k / 2000.0) * step, distance));
    EXPECT_GT(least, 0.0) << "case " << i;
    EXPECT_GE(room(set[0], x + alpha * step, distance), 0.05 * r0) << "case " << i;
  }
  EXPECT_GT(limited, 100);
  // A step that sinks slowly while it slides over the top of the sphere, from 0.99 d̂ deep: r(t)
  // is convex, and between the samples around its crossing of r₀/10 the interpolated α lies
  // past r = 0 (r(α) = −0.03 r₀ without the halving).
  const Vector3d top(0.0, 0.0, 1.0 - distance + 1e-4);
  const Vector3d sinking(0.03, 0.0, -6.9e-4);
  const ContactTerm term(obstacles, std::vector<int>{0}, {distance, 50.0, 1e-4});
  const double alpha = term.max_step(top, sinking);
  EXPECT_GE(room(obstacles[0], top + alpha * sinking, distance), 0.05e-4);
  EXPECT_GT(alpha, 0.9e-4 / sinking.norm());
}

TEST(ContactScenes, BlockPressedOntoAPlaneCarriesTheLoad) {
  DirichletSpec roller;
  roller.name = "roller";
  roller.region = PlaneRegion{Vector3d(0, 0, 0.1), Vector3d::UnitZ(), 0.0};
  roller.components = {true, true, false};
  const double load = 2000.0;  // 0.2 MPa on the top face: 2 % strain
  RegionLoad press{"press", PlaneRegion{Vector3d(0, 0, 0.1), Vector3d::UnitZ(), 0.0},
                   Vector3d(0, 0, -load)};
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 4;
  Simulation sim(cube(),
                 {.material = rubber(),
                  .dirichlet = {roller},
                  .loads = {press},
                  .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
                 settings);
  while (!sim.finished())
    sim.advance();
  const VectorXd f = sim.contact_forces();
  Vector3d total = Vector3d::Zero();
  for (Index v = 0; v < f.size() / 3; ++v)
    total += f.segment<3>(3 * v);
  EXPECT_NEAR(total.z(), load, 1e-6 * load);
  EXPECT_NEAR(total.head<2>().norm(), 0.0, 1e-6 * load);
  EXPECT_GT(sim.max_penetration(), 0.0);
  EXPECT_LE(sim.max_penetration(), sim.contact_settings().distance);
  EXPECT_EQ(sim.contact_counts().size(), 4u);
  EXPECT_EQ(sim.contact_counts().back(), 9);  // the 3 × 3 bottom vertices
}

struct SlopeRun {
  double drift = 0.0;         ///< largest |Δx| of the centre of mass along the slope [m]
  double acceleration = 0.0;  ///< centre-of-mass acceleration along the slope, 0.15–0.35 s
  double max_penetration = 0.0;
  double tolerance = 0.0;
};

/// The cube on the plane z = 0 with μ = 0.5 (friction angle 26.6°) under gravity tilted by θ
/// towards +x, backward Euler for 0.35 s.
SlopeRun slope(double degrees) {
  const double theta = degrees * std::numbers::pi / 180.0;
  const double g = 9.81;
  Obstacle ground = plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ());
  ground.friction = 0.5;
  SolverSettings settings;
  settings.dt = 1e-3;
  settings.duration = 0.35;
  const TetMesh mesh = cube();
  Simulation sim(mesh,
                 {.material = rubber(),
                  .gravity = Vector3d(g * std::sin(theta), 0, -g * std::cos(theta)),
                  .obstacles = {ground}},
                 settings);
  const VectorXd& m = sim.vertex_mass();
  const auto centre = [&](const VectorXd& values) {
    Vector3d sum = Vector3d::Zero();
    for (Index v = 0; v < m.size(); ++v)
      sum += m[v] * values.segment<3>(3 * v);
    return Vector3d(sum / m.sum());
  };
  const Vector3d start = centre(sim.positions());
  SlopeRun run;
  double v1 = 0.0, t1 = 0.0;
  while (!sim.finished()) {
    sim.advance();
    run.drift = std::max(run.drift, std::abs(centre(sim.positions()).x() - start.x()));
    if (std::abs(sim.time() - 0.15) < 1e-9) {
      v1 = centre(sim.velocities()).x();
      t1 = sim.time();
    }
  }
  run.acceleration = (centre(sim.velocities()).x() - v1) / (sim.time() - t1);
  run.max_penetration = sim.max_penetration();
  run.tolerance = sim.contact_settings().distance;
  return run;
}

TEST(ContactScenes, BlockOnASlopeSticksBelowTheFrictionAngle) {
  const SlopeRun run = slope(15.0);
  EXPECT_LT(run.drift, run.tolerance);
  EXPECT_LE(run.max_penetration, run.tolerance);
}

TEST(ContactScenes, BlockOnASlopeSlidesWithTheCoulombAcceleration) {
  const double theta = 35.0 * std::numbers::pi / 180.0;
  const double expected = 9.81 * (std::sin(theta) - 0.5 * std::cos(theta));
  const SlopeRun run = slope(35.0);
  EXPECT_NEAR(run.acceleration, expected, 0.02 * expected);
  EXPECT_LE(run.max_penetration, run.tolerance);
}

TEST(ContactScenes, BlockDroppedOnASphereStaysWithinTheTolerance) {
  const TetMesh mesh =
      box_tet_mesh(Vector3d(-0.05, -0.05, 0.22), Vector3d(0.05, 0.05, 0.32), {2, 2, 2});
  SolverSettings settings;
  settings.dt = 1e-3;
  settings.duration = 0.4;
  Simulation sim(mesh,
                 {.material = rubber(),
                  .gravity = Vector3d(0, 0, -9.81),
                  .obstacles = {sphere_obstacle(Vector3d::Zero(), 0.2)}},
                 settings);
  double lowest = 1.0;
  while (!sim.finished()) {
    sim.advance();
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      lowest = std::min(lowest, sim.positions().segment<3>(3 * v).norm() - 0.2);
  }
  EXPECT_GT(sim.max_penetration(), 0.0);  // it landed
  EXPECT_LE(sim.max_penetration(), sim.contact_settings().distance);
  EXPECT_GE(lowest, -sim.contact_settings().distance);
  EXPECT_GT(*std::max_element(sim.contact_counts().begin(), sim.contact_counts().end()), 0);
}

TEST(ContactScenes, PointsBoundByWeightsCarryTheBodyWhereItsVerticesDoNotTouch) {
  // A block 5 cm above a plane; extra contact points extrapolated half a block height below its
  // bottom vertices (weights 1.5 and −0.5 on a vertical edge, as a bound fine surface outside the
  // coarse mesh gets) touch the plane: they, not the vertices, hold it up.
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0.05), Vector3d(0.1, 0.1, 0.15), {1, 1, 1});
  SimulationOptions options;
  for (Index bottom = 0; bottom < mesh.vertices.rows(); ++bottom) {
    if (mesh.vertices(bottom, 2) > 0.05 + 1e-12) continue;
    for (Index top = 0; top < mesh.vertices.rows(); ++top)
      if (mesh.vertices(top, 2) > 0.15 - 1e-12 &&
          (mesh.vertices.row(top).head<2>() - mesh.vertices.row(bottom).head<2>()).norm() < 1e-12)
        options.contact_points.push_back(
            {{static_cast<int>(bottom), static_cast<int>(top)}, {1.5, -0.5}});
  }
  ASSERT_EQ(options.contact_points.size(), 4u);
  SolverSettings settings;
  settings.dt = 2e-3;
  settings.duration = 0.3;
  Material material = rubber();
  material.mass_damping = 20.0;  // settle
  Simulation sim(mesh,
                 {.material = material,
                  .gravity = Vector3d(0, 0, -9.81),
                  .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
                 settings, std::move(options));
  while (!sim.finished())
    sim.advance();
  double lowest = 1.0;
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    lowest = std::min(lowest, sim.positions()[3 * v + 2]);
  EXPECT_GT(lowest, 0.04);  // the block's own vertices stay well above the plane
  const VectorXd f = sim.contact_forces();
  double lift = 0.0;
  for (Index v = 0; v < f.size() / 3; ++v)
    lift += f[3 * v + 2];
  const double weight = sim.vertex_mass().sum() * 9.81;
  EXPECT_NEAR(lift, weight, 0.02 * weight);  // at rest: the points carry the weight
  EXPECT_LE(sim.max_penetration(), sim.contact_settings().distance);
}

/// `mesh` under gravity above the ground z = 0, symplectic Euler steps of 20 µs for `duration`.
std::unique_ptr<Simulation> explicit_on_ground(const TetMesh& mesh, const Material& material,
                                               double duration) {
  SolverSettings settings;
  settings.integrator = Integrator::symplectic_euler;
  settings.dt = 2e-5;
  settings.duration = duration;
  return std::make_unique<Simulation>(
      mesh,
      ProblemSpec{.material = material,
                  .gravity = Vector3d(0, 0, -9.81),
                  .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
      settings);
}

TEST(ContactScenes, ExplicitStepsProjectOntoTheObstacle) {
  TetMesh mesh = cube();
  mesh.vertices.col(2).array() += 0.001;
  const std::unique_ptr<Simulation> run = explicit_on_ground(mesh, rubber(), 0.02);
  Simulation& sim = *run;
  VectorXd v = VectorXd::Zero(sim.dof_velocities().size());
  for (Index i = 2; i < v.size(); i += 3)
    v[i] = -0.5;
  sim.set_state(sim.dof_positions(), v);
  while (!sim.finished())
    sim.advance();
  for (Index i = 2; i < sim.positions().size(); i += 3)
    EXPECT_GE(sim.positions()[i], -1e-12);
}

TEST(ContactScenes, ExplicitStepsReportTheProjectedContactsAndTheirForces) {
  // The cube resting on the ground under gravity, symplectic Euler, damped to rest: each step's
  // projection is its contact. The 3 × 3 bottom vertices are in contact, the depth they reached
  // before the projection is reported, and the contact forces (the momentum the projection
  // changes, M Δv / h) carry the cube's weight, averaged over the last 10 ms.
  Material material = rubber();
  material.mass_damping = 100.0;
  const double duration = 0.1;
  const std::unique_ptr<Simulation> run = explicit_on_ground(cube(), material, duration);
  Simulation& sim = *run;
  const double dt = sim.settings().dt;
  const double weight = 9.81 * sim.vertex_mass().sum();
  double impulse = 0.0, elapsed = 0.0;
  while (!sim.finished()) {
    sim.advance();
    if (sim.time() <= duration - 0.01 + 1e-12) continue;
    const VectorXd f = sim.contact_forces();
    double fz = 0.0;
    for (Index v = 0; v < f.size() / 3; ++v)
      fz += f[3 * v + 2];
    impulse += fz * dt;
    elapsed += dt;
  }
  EXPECT_NEAR(impulse / elapsed, weight, 0.01 * weight);
  EXPECT_EQ(sim.contact_counts().size(), static_cast<std::size_t>(sim.step_count()));
  EXPECT_EQ(sim.contact_counts().back(), 9);
  // Each step the bottom sinks by about g h² before it is projected back.
  EXPECT_GT(sim.max_penetration(), 0.0);
  EXPECT_LT(sim.max_penetration(), 1e-6);
  // Only the bottom vertices carry contact forces.
  const VectorXd on_mesh = sim.mesh_contact_forces();
  for (Index v = 0; v < sim.mesh().vertices.rows(); ++v)
    if (sim.mesh().vertices(v, 2) > 1e-9) {
      EXPECT_TRUE(on_mesh.segment<3>(3 * v).isZero());
    }
  // A state set from outside has not been projected: no forces until the next step.
  sim.set_state(sim.dof_positions(), sim.dof_velocities());
  EXPECT_TRUE(sim.contact_forces().isZero());
}

TEST(ContactScenes, AnObstacleThatReachesAHeldPointIsNamedInTheError) {
  // A wall moving at 0.1 m/s towards the cube's x = 0.1 face, 0.3 mm away, while the cube's
  // bottom face is clamped: within a few 4 ms steps the wall passes the clamped vertices on that
  // face, which cannot give way, and squeezes the free ones beside them. The error says so, and
  // why Newton stopped.
  DirichletSpec clamp;
  clamp.name = "fixed[0]";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitZ(), 0.0};
  Obstacle wall = plane_obstacle("obstacles.0", Vector3d(0.1003, 0, 0), -Vector3d::UnitX());
  wall.velocity = Vector3d(-0.1, 0, 0);
  SolverSettings settings;
  settings.dt = 4e-3;
  settings.duration = 0.02;
  Simulation sim(cube(), {.material = rubber(), .dirichlet = {clamp}, .obstacles = {wall}},
                 settings);
  try {
    while (!sim.finished())
      sim.advance();
    FAIL() << "no error";
  } catch (const DivergenceError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("Newton did not converge at step "), std::string::npos) << message;
    EXPECT_NE(message.find(", stopped at "), std::string::npos) << message;
    EXPECT_NE(message.find("obstacles.0 has reached a point held by fixed[0] at (0.1, "),
              std::string::npos)
        << message;
  }
}

TEST(ContactScenes, StartingInsideAnObstacleIsAnError) {
  SolverSettings settings;
  try {
    Simulation sim(
        cube(),
        {.material = rubber(),
         .obstacles = {plane_obstacle("obstacles.0", Vector3d(0, 0, 0.05), Vector3d::UnitZ())}},
        settings);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("obstacles.0: contact point"), std::string::npos)
        << error.what();
  }
  // A sphere wholly inside the cube touches no contact point: it could never act.
  try {
    Simulation sim(
        cube(),
        {.material = rubber(), .obstacles = {sphere_obstacle(Vector3d(0.05, 0.05, 0.05), 0.01)}},
        settings);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("inside the obstacle: the obstacle overlaps the "
                        "body's inside"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace strata
