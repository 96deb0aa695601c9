// The skeleton-spring body: CGAL's curve skeleton of a beam and of a scanned model (connected,
// inside the surface), rigid motions leave every spring at rest, and a cantilever bends with the
// stiffness the rule predicts (Euler–Bernoulli, within a stated factor).
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/spring_body.hpp"
#include "strata/meshing/curve_skeleton.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/triangle_bvh.hpp"

namespace strata {
namespace {

/// The boundary of a box tet mesh as a closed, outward surface with only its own vertices.
SurfaceMesh beam_surface(const Vector3d& lo, const Vector3d& hi, const std::array<int, 3>& cells) {
  const TetMesh mesh = box_tet_mesh(lo, hi, cells);
  const MatrixX3i faces = boundary_faces(mesh.tets);
  std::vector<int> index(mesh.vertices.rows(), -1);
  SurfaceMesh surface;
  std::vector<Vector3d> points;
  surface.triangles.resize(faces.rows(), 3);
  for (Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      int& i = index[faces(f, k)];
      if (i < 0) {
        i = static_cast<int>(points.size());
        points.push_back(mesh.vertices.row(faces(f, k)).transpose());
      }
      surface.triangles(f, k) = i;
    }
  surface.vertices.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    surface.vertices.row(static_cast<Index>(i)) = points[i].transpose();
  if (enclosed_volume(surface) < 0.0) surface.triangles.col(1).swap(surface.triangles.col(2));
  return surface;
}

Material steel_like() {
  Material material;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

SpringBody body_of(const SurfaceMesh& surface, const CurveSkeleton& skeleton,
                   const SpringBodyRule& rule = {}) {
  std::vector<std::array<int, 2>> segments;
  for (Index e = 0; e < skeleton.edges.rows(); ++e)
    segments.push_back({skeleton.edges(e, 0), skeleton.edges(e, 1)});
  return skeleton_spring_body(surface.vertices, surface.triangles, skeleton.points, segments,
                              skeleton.owner, steel_like(), rule, "body");
}

void expect_inside(const SurfaceMesh& surface, const CurveSkeleton& skeleton) {
  const TriangleBvh bvh(surface.vertices, surface.triangles);
  for (Index k = 0; k < skeleton.points.rows(); ++k)
    EXPECT_GT(bvh.winding_number(skeleton.points.row(k).transpose(), 0.0), 0.5) << "point " << k;
}

TEST(CurveSkeleton, OfABeamIsAConnectedLineAlongItsAxis) {
  const SurfaceMesh surface = beam_surface(Vector3d::Zero(), Vector3d(1, 0.1, 0.1), {40, 4, 4});
  const CurveSkeleton skeleton = curve_skeleton(surface, "beam");
  ASSERT_GT(skeleton.points.rows(), 5);
  EXPECT_TRUE(is_connected(skeleton));
  EXPECT_EQ(skeleton.edges.rows(), skeleton.points.rows() - 1);  // a tree without branches here
  expect_inside(surface, skeleton);
  for (Index k = 0; k < skeleton.points.rows(); ++k) {
    EXPECT_NEAR(skeleton.points(k, 1), 0.05, 0.01);
    EXPECT_NEAR(skeleton.points(k, 2), 0.05, 0.01);
  }
  EXPECT_EQ(skeleton.owner.size(), surface.vertices.rows());
  EXPECT_GE(skeleton.owner.minCoeff(), 0);
}

TEST(CurveSkeleton, RejectsAnOpenSurface) {
  SurfaceMesh surface = beam_surface(Vector3d::Zero(), Vector3d(1, 0.1, 0.1), {10, 2, 2});
  surface.triangles.conservativeResize(surface.triangles.rows() - 1, 3);
  EXPECT_THROW(curve_skeleton(surface, "open"), InputError);
}

TEST(SkeletonSprings, ARigidMotionLeavesEverySpringAtRest) {
  const SurfaceMesh surface = beam_surface(Vector3d::Zero(), Vector3d(1, 0.1, 0.1), {20, 2, 2});
  const SpringBody body = body_of(surface, curve_skeleton(surface, "beam"));
  EXPECT_GT(body.count(SpringKind::surface), 0);
  EXPECT_GE(body.count(SpringKind::tie), surface.vertices.rows());
  EXPECT_GT(body.count(SpringKind::skeleton), 0);
  EXPECT_NEAR(body.vertex_mass.sum(), 1000.0 * 0.01, 1e-9);
  EXPECT_NEAR(body.volume, 0.01, 1e-12);
  const Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  VectorXd x(3 * body.rest.rows());
  for (Index i = 0; i < body.rest.rows(); ++i)
    x.segment<3>(3 * i) = R * body.rest.row(i).transpose() + Vector3d(0.3, -2, 5);
  EXPECT_LT(body.springs.energy(x), 1e-20);
  VectorXd f = VectorXd::Zero(x.size());
  body.springs.add_forces(x, f);
  // Round-off only: far below the force of a unit strain, k L₀.
  EXPECT_LT(f.cwiseAbs().maxCoeff(),
            1e-12 * body.springs.stiffness.cwiseProduct(body.springs.rest).maxCoeff());
  // A stretch is not at rest.
  x *= 1.01;
  EXPECT_GT(body.springs.energy(x), 0.0);
}

/// Tip deflection of a cantilever (clamped at x = 0, load F on the end face, heavily damped to
/// rest) against Euler–Bernoulli, δ = F L³ / (3 E I).
double cantilever_ratio(double width, const std::array<int, 3>& cells) {
  const double L = 1.0, F = -0.02;
  const SurfaceMesh surface = beam_surface(Vector3d::Zero(), Vector3d(L, width, width), cells);
  Material light = steel_like();
  light.density = 1.0;
  std::vector<std::array<int, 2>> segments;
  const CurveSkeleton skeleton = curve_skeleton(surface, "beam");
  for (Index e = 0; e < skeleton.edges.rows(); ++e)
    segments.push_back({skeleton.edges(e, 0), skeleton.edges(e, 1)});
  SpringBody body = skeleton_spring_body(surface.vertices, surface.triangles, skeleton.points,
                                         segments, skeleton.owner, light, {}, "body");
  DirichletSpec clamp;
  clamp.name = "fixed.0";
  clamp.region = BoxRegion{Vector3d(-1, -1, -1), Vector3d(0.02 * L, 1, 1)};
  RegionLoad load;
  load.name = "forces.0";
  load.region = BoxRegion{Vector3d(L, -1, -1), Vector3d(2, 1, 1)};
  load.total_force = Vector3d(0, 0, F);
  // Light and damped near critically (lowest bending mode ≈ 3 rad/s): at rest well before the
  // end of the run.
  Material material = steel_like();
  material.density = 1.0;
  material.mass_damping = 6.0;
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 0.05;
  settings.duration = 20.0;
  SpringBodySimulation run(std::move(body),
                           {.material = material, .dirichlet = {clamp}, .loads = {load}}, settings);
  while (!run.finished())
    run.advance();
  double tip = 0.0;
  const VectorXd& x = run.positions();
  for (Index i = 0; i < run.body().num_surface; ++i)
    if (run.body().rest(i, 0) > L - 1e-9) tip += (x[3 * i + 2] - run.body().rest(i, 2));
  Index count = 0;
  for (Index i = 0; i < run.body().num_surface; ++i)
    if (run.body().rest(i, 0) > L - 1e-9) ++count;
  tip /= static_cast<double>(count);
  const double I = std::pow(width, 4) / 12.0;
  const double predicted = F * L * L * L / (3.0 * material.youngs_modulus * I);
  return tip / predicted;
}

TEST(SkeletonSprings, ABeamDroppedOnAPlaneRestsOnItWithinTheTolerance) {
  // The surface vertices contact obstacles as a tet mesh's do: a beam dropped 2 cm onto a plane
  // never gets deeper than the tolerance and comes to rest on it.
  const SurfaceMesh surface =
      beam_surface(Vector3d(0, 0, 0.02), Vector3d(0.5, 0.1, 0.12), {10, 2, 2});
  Material material = steel_like();
  material.mass_damping = 20.0;
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 0.01;
  settings.duration = 1.0;
  SpringBodySimulation run(
      body_of(surface, curve_skeleton(surface, "beam")),
      {.material = material,
       .gravity = Vector3d(0, 0, -9.81),
       .obstacles = {plane_obstacle("ground", Vector3d::Zero(), Vector3d::UnitZ())}},
      settings);
  ASSERT_TRUE(run.has_obstacles());
  while (!run.finished())
    run.advance();
  const double tolerance = run.contact_settings().distance;
  EXPECT_GT(run.max_penetration(), 0.0);  // it landed
  EXPECT_LE(run.max_penetration(), tolerance);
  EXPECT_GT(run.contact_counts().back(), 0);
  EXPECT_EQ(static_cast<long>(run.contact_counts().size()), run.step_count());
  double lowest = 1.0;
  for (Index i = 0; i < run.body().num_surface; ++i)
    lowest = std::min(lowest, run.positions()[3 * i + 2]);
  EXPECT_GE(lowest, -tolerance);
  EXPECT_LT(lowest, 0.005);  // on the plane, not above it
  EXPECT_LT(run.kinetic_energy(), 1e-6 * run.body().vertex_mass.sum() * 9.81 * 0.02);
  // A body that starts inside an obstacle is an error naming it.
  EXPECT_THROW(
      SpringBodySimulation(
          body_of(surface, curve_skeleton(surface, "beam")),
          {.material = material,
           .obstacles = {plane_obstacle("floor", Vector3d(0, 0, 0.05), Vector3d::UnitZ())}},
          settings),
      InputError);
}

TEST(SkeletonSprings, ACantileverBendsWithTheStiffnessTheRulePredicts) {
  // The rule matches a solid circular section; for these square ones it is stated within a factor
  // of 1.5 of Euler–Bernoulli (measured: 0.72 and 0.86 of the deflection, the README).
  for (const double width : {0.1, 0.15}) {
    const double ratio = cantilever_ratio(width, {40, 4, 4});
    EXPECT_GT(ratio, 1.0 / 1.5) << width;
    EXPECT_LT(ratio, 1.5) << width;
    std::printf("cantilever %.2f: tip deflection / Euler-Bernoulli = %.3f\n", width, ratio);
  }
}

TEST(CurveSkeleton, OfTheArmadilloIsConnectedAndInside) {
  const std::filesystem::path models = STRATA_MODELS_DIR;
  if (!std::filesystem::exists(models / "armadillo.off")) GTEST_SKIP() << "no armadillo.off";
  const SurfaceMesh armadillo = read_surface(models / "armadillo.off");
  const CurveSkeleton skeleton = curve_skeleton(armadillo, "armadillo");
  EXPECT_TRUE(is_connected(skeleton));
  EXPECT_GT(skeleton.points.rows(), 20);
  expect_inside(armadillo, skeleton);
  std::printf("armadillo: %lld skeleton points, %lld segments in %.2f s\n",
              static_cast<long long>(skeleton.points.rows()),
              static_cast<long long>(skeleton.edges.rows()), skeleton.seconds);
  const SpringBody body = body_of(armadillo, skeleton);
  EXPECT_NEAR(body.vertex_mass.sum(), 1000.0 * body.volume, 1e-9 * body.vertex_mass.sum());
}

TEST(CurveSkeleton, DoesNotDependOnTheHeap) {
  // CGAL's skeletonization orders its edge collapses by element address; with the general heap
  // the skeleton changed with whatever the process had allocated before (seen: 562 to 591 points
  // for the armadillo). Skeletonize, fragment the heap with freed blocks of the sizes of CGAL's
  // elements, skeletonize again: the skeletons must be identical.
  const std::filesystem::path models = STRATA_MODELS_DIR;
  if (!std::filesystem::exists(models / "armadillo.off")) GTEST_SKIP() << "no armadillo.off";
  const SurfaceMesh armadillo = read_surface(models / "armadillo.off");
  const CurveSkeleton first = curve_skeleton(armadillo, "armadillo");
  std::vector<std::unique_ptr<char[]>> blocks;
  for (int k = 0; k < 200000; ++k)
    blocks.push_back(std::make_unique<char[]>(16 + 8 * (k % 31)));
  for (std::size_t k = 0; k < blocks.size(); k += 2)
    blocks[k].reset();
  const CurveSkeleton second = curve_skeleton(armadillo, "armadillo");
  ASSERT_EQ(first.points.rows(), second.points.rows());
  EXPECT_EQ(first.points, second.points);
  EXPECT_EQ(first.edges, second.edges);
  EXPECT_EQ(first.owner, second.owner);
}

}  // namespace
}  // namespace strata
