#include <gtest/gtest.h>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/region.hpp"

namespace strata {
namespace {

TEST(SimRegion, BoxIsInclusiveWithinTolerance) {
  // 2 × 1 × 1 box with 2 × 1 × 1 cells: vertices at x ∈ {0, 1, 2}.
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), {2, 1, 1});
  const double tol = region_tolerance(mesh.vertices);
  EXPECT_NEAR(tol, 1e-9 * std::sqrt(6.0), 1e-20);
  // A box whose face sits exactly on the plane x = 1 selects that layer (4 vertices) ...
  std::vector<int> layer =
      select_vertices(BoxRegion{Vector3d(1, -1, -1), Vector3d(1, 2, 2)}, mesh.vertices, tol);
  EXPECT_EQ(layer.size(), 4u);
  for (int v : layer)
    EXPECT_DOUBLE_EQ(mesh.vertices(v, 0), 1.0);
  // ... and so does one that misses it by less than the tolerance (round-off in scene input),
  layer = select_vertices(BoxRegion{Vector3d(1 + 0.1 * tol, -1, -1), Vector3d(3, 2, 2)},
                          mesh.vertices, tol);
  EXPECT_EQ(layer.size(), 8u);
  // but not one that misses it by more.
  layer = select_vertices(BoxRegion{Vector3d(1 + 10 * tol, -1, -1), Vector3d(3, 2, 2)},
                          mesh.vertices, tol);
  EXPECT_EQ(layer.size(), 4u);
}

TEST(SimRegion, PlaneAndSphere) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), {2, 1, 1});
  const double tol = region_tolerance(mesh.vertices);
  // Plane x = 2 given with a non-unit normal; distance 0 → the end face only.
  std::vector<int> end =
      select_vertices(PlaneRegion{Vector3d(2, 5, 5), Vector3d(-3, 0, 0), 0.0}, mesh.vertices, tol);
  EXPECT_EQ(end.size(), 4u);
  // Slab of half-width 1 around x = 2 also takes the middle layer.
  end = select_vertices(PlaneRegion{Vector3d(2, 0, 0), Vector3d(1, 0, 0), 1.0}, mesh.vertices, tol);
  EXPECT_EQ(end.size(), 8u);
  // Sphere of radius √2 around (0,0,0): vertices with |X|² ≤ 2, boundary included:
  // (0,0,0), (1,0,0), (0,1,0), (0,0,1), (1,1,0), (1,0,1), (0,1,1).
  const std::vector<int> ball =
      select_vertices(SphereRegion{Vector3d::Zero(), std::sqrt(2.0)}, mesh.vertices, tol);
  EXPECT_EQ(ball.size(), 7u);
}

TEST(SimRegion, MalformedRegionsAreInputErrors) {
  EXPECT_THROW(validate_region(BoxRegion{Vector3d(1, 0, 0), Vector3d(0, 1, 1)}, "r"), InputError);
  EXPECT_THROW(validate_region(PlaneRegion{Vector3d::Zero(), Vector3d::Zero(), 0.0}, "r"),
               InputError);
  EXPECT_THROW(validate_region(SphereRegion{Vector3d::Zero(), -1.0}, "r"), InputError);
}

TEST(SimDirichlet, EmptyGroupIsNamedAndLaterGroupsWin) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), {2, 1, 1});
  const double tol = region_tolerance(mesh.vertices);
  DirichletSpec empty;
  empty.name = "fixed[1]";
  empty.region = BoxRegion{Vector3d(5, 5, 5), Vector3d(6, 6, 6)};
  try {
    resolve_dirichlet_groups({empty}, mesh.vertices, tol);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "fixed[1]: region selects no vertex");
  }
  DirichletSpec first;
  first.name = "fixed[0]";
  first.region = BoxRegion{Vector3d(-1, -1, -1), Vector3d(1, 2, 2)};  // x ≤ 1: 8 vertices
  DirichletSpec second;
  second.name = "displacement[0]";
  second.kind = DirichletKind::displacement;
  second.displacement = Vector3d(0.1, 0, 0);
  second.region = BoxRegion{Vector3d(1, -1, -1), Vector3d(3, 2, 2)};  // x ≥ 1: 8 vertices
  const auto groups = resolve_dirichlet_groups({first, second}, mesh.vertices, tol);
  EXPECT_EQ(groups[0].vertices.size(), 4u);  // the shared layer x = 1 went to the later group
  EXPECT_EQ(groups[1].vertices.size(), 8u);
  EXPECT_TRUE(groups[1].moment_center.isApprox(Vector3d(1.5, 0.5, 0.5)));
}

TEST(SimDirichlet, FreeRigidMotionsCountWhatTheConstraintsLeave) {
  // Vertices of a unit cube's corners, as a 3·#V rest vector.
  VectorXd rest(3 * 8);
  for (int i = 0; i < 8; ++i)
    rest.segment<3>(3 * i) = Vector3d(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const auto group = [](std::vector<int> vertices,
                        std::array<bool, 3> components = {true, true, true}) {
    DirichletGroup result;
    result.vertices = std::move(vertices);
    result.spec.components = components;
    return result;
  };
  EXPECT_EQ(free_rigid_motions({}, rest), 6);
  EXPECT_EQ(free_rigid_motions({group({0})}, rest), 3);              // turns about the vertex
  EXPECT_EQ(free_rigid_motions({group({0, 1})}, rest), 1);           // turns about the edge's line
  EXPECT_EQ(free_rigid_motions({group({0, 3})}, rest), 1);           // a face diagonal: a line too
  EXPECT_EQ(free_rigid_motions({group({0, 1, 2})}, rest), 0);        // three points not on one line
  EXPECT_EQ(free_rigid_motions({group({0}), group({7})}, rest), 1);  // groups add up
  // Rollers: x held on the face x = 0 leaves the y, z slides and the turn about x.
  EXPECT_EQ(free_rigid_motions({group({0, 2, 4, 6}, {true, false, false})}, rest), 3);
  // z held on the bottom face, and x, y at one corner: only the turn about z at that corner.
  EXPECT_EQ(free_rigid_motions(
                {group({0, 1, 2, 3}, {false, false, true}), group({0}, {true, true, false})}, rest),
            1);
  EXPECT_EQ(free_rigid_motions({group({0, 1, 2, 3}, {false, false, true}),
                                group({0}, {true, true, false}), group({1}, {false, true, false})},
                               rest),
            0);
}

TEST(SimDirichlet, RotationTargetsAreRigidAndVelocitiesMatchDerivatives) {
  DirichletGroup group;
  group.spec.kind = DirichletKind::rotation;
  group.spec.axis = Vector3d(1, 2, 2);
  group.spec.angle = 1.3;
  group.moment_center = Vector3d(0.3, -0.2, 0.1);
  const Vector3d X(1.0, 0.5, -0.7), Y(-0.4, 0.9, 0.2);
  const double s = 0.6, ds_dt = 2.0, dt = 1e-6;
  const Vector3d x = group.target_position(X, s), y = group.target_position(Y, s);
  EXPECT_NEAR((x - y).norm(), (X - Y).norm(), 1e-14);
  // A point on the axis stays.
  const Vector3d on_axis = group.moment_center + 0.7 * group.spec.axis;
  EXPECT_TRUE(group.target_position(on_axis, s).isApprox(on_axis, 1e-14));
  // Velocity and acceleration against central differences in time (s = s0 + ds_dt · t).
  const Vector3d fd_velocity =
      (group.target_position(X, s + ds_dt * dt) - group.target_position(X, s - ds_dt * dt)) /
      (2 * dt);
  EXPECT_LT((group.target_velocity(X, s, ds_dt) - fd_velocity).norm(), 1e-7);
  const double dt2 = 1e-4;
  const Vector3d fd_acceleration = (group.target_position(X, s + ds_dt * dt2) - 2 * x +
                                    group.target_position(X, s - ds_dt * dt2)) /
                                   (dt2 * dt2);
  EXPECT_LT((group.target_acceleration(X, s, ds_dt) - fd_acceleration).norm(), 1e-5);
}

}  // namespace
}  // namespace strata
