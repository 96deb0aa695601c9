// Point location: barycentric coordinates reproduce the point, the grid search agrees with a brute
// force scan, tolerance handling for points just outside, and errors for points far outside.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

Vector3d vertex(const TetMesh& mesh, Index tet, int k) {
  return mesh.vertices.row(mesh.tets(tet, k)).transpose();
}

Vector3d interpolate(const TetMesh& mesh, const TetLocation& location) {
  Vector3d p = Vector3d::Zero();
  for (int k = 0; k < 4; ++k)
    p += location.barycentric(k) * vertex(mesh, location.tet, k);
  return p;
}

TEST(PointLocation, BarycentricCoordinatesOfAUnitTet) {
  const Vector3d x0(0, 0, 0), x1(1, 0, 0), x2(0, 1, 0), x3(0, 0, 1);
  const Eigen::Vector4d l = tet_barycentric_coordinates(Vector3d(0.1, 0.2, 0.3), x0, x1, x2, x3);
  EXPECT_NEAR(l(0), 0.4, 1e-15);
  EXPECT_NEAR(l(1), 0.1, 1e-15);
  EXPECT_NEAR(l(2), 0.2, 1e-15);
  EXPECT_NEAR(l(3), 0.3, 1e-15);
}

TEST(PointLocation, PointTetDistanceMatchesGeometry) {
  const Vector3d x0(0, 0, 0), x1(1, 0, 0), x2(0, 1, 0), x3(0, 0, 1);
  EXPECT_EQ(point_tet_distance(Vector3d(0.1, 0.1, 0.1), x0, x1, x2, x3), 0.0);
  // Closest point inside the face x = 0.
  EXPECT_NEAR(point_tet_distance(Vector3d(-1, 0.2, 0.2), x0, x1, x2, x3), 1.0, 1e-14);
  // Closest point (1/3, 1/3, 1/3) on the slanted face.
  EXPECT_NEAR(point_tet_distance(Vector3d(1, 1, 1), x0, x1, x2, x3), 2.0 / std::sqrt(3.0), 1e-14);
  // Closest point is the vertex x1.
  EXPECT_NEAR(point_tet_distance(Vector3d(2, -1, -1), x0, x1, x2, x3), std::sqrt(3.0), 1e-14);
  // Closest point on the edge x0–x1.
  EXPECT_NEAR(point_tet_distance(Vector3d(0.5, -1, -1), x0, x1, x2, x3), std::sqrt(2.0), 1e-14);
}

TEST(PointLocation, LocatedTetContainsThePointAndCoordinatesReproduceIt) {
  TetMesh mesh = box_tet_mesh(Vector3d(-1, 0, 0), Vector3d(2, 0.5, 0.25), {12, 3, 2});
  // Perturb interior vertices so the mesh is irregular.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  const auto [lo, hi] = bounding_box(mesh.vertices);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d x = mesh.vertices.row(v).transpose();
    const bool interior = ((x - lo).array() > 1e-12).all() && ((hi - x).array() > 1e-12).all();
    if (interior) mesh.vertices.row(v) += Eigen::RowVector3d(jitter(rng), jitter(rng), jitter(rng));
  }
  const TetLocator locator(mesh.vertices, mesh.tets);
  std::uniform_real_distribution<double> ux(-1, 2), uy(0, 0.5), uz(0, 0.25);
  for (int i = 0; i < 500; ++i) {
    const Vector3d p(ux(rng), uy(rng), uz(rng));
    const std::optional<TetLocation> location = locator.locate(p, 0.0);
    ASSERT_TRUE(location.has_value()) << i;
    EXPECT_EQ(location->distance, 0.0);
    EXPECT_NEAR(location->barycentric.sum(), 1.0, 1e-12);
    EXPECT_GE(location->barycentric.minCoeff(), -1e-12);
    EXPECT_LT((interpolate(mesh, *location) - p).norm(), 1e-12);
    // Brute force: the point lies in the returned tet and in no tet's interior strictly more.
    int containing = 0;
    for (Index t = 0; t < mesh.tets.rows(); ++t) {
      const Eigen::Vector4d l = tet_barycentric_coordinates(
          p, vertex(mesh, t, 0), vertex(mesh, t, 1), vertex(mesh, t, 2), vertex(mesh, t, 3));
      containing += l.minCoeff() >= -1e-12;
    }
    EXPECT_GE(containing, 1);
  }
}

TEST(PointLocation, VerticesAndBoundaryPointsAreFound) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.1, 0.1), {5, 1, 1});
  const TetLocator locator(mesh.vertices, mesh.tets);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d p = mesh.vertices.row(v).transpose();
    const std::optional<TetLocation> location = locator.locate(p, 0.0);
    ASSERT_TRUE(location.has_value()) << v;
    EXPECT_LT((interpolate(mesh, *location) - p).norm(), 1e-14);
    // The vertex's own coordinate is 1 (it is a vertex of the tet found).
    EXPECT_NEAR(location->barycentric.maxCoeff(), 1.0, 1e-12);
  }
}

TEST(PointLocation, ToleranceDecidesForPointsJustOutside) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 1), {3, 3, 3});
  const TetLocator locator(mesh.vertices, mesh.tets);
  const Vector3d p(1.0 + 1e-6, 0.4, 0.7);
  EXPECT_FALSE(locator.locate(p, 1e-7).has_value());
  const std::optional<TetLocation> location = locator.locate(p, 1e-5);
  ASSERT_TRUE(location.has_value());
  EXPECT_NEAR(location->distance, 1e-6, 1e-12);
  // The coordinates still reproduce the (outside) point: a tiny linear extrapolation.
  EXPECT_LT((interpolate(mesh, *location) - p).norm(), 1e-12);
  EXPECT_LT(location->barycentric.minCoeff(), 0.0);
}

TEST(PointLocation, FarOutsidePointsAreErrorsNamingTheIndex) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 1), {2, 2, 2});
  const TetLocator locator(mesh.vertices, mesh.tets);
  EXPECT_FALSE(locator.locate(Vector3d(5, 0.5, 0.5), 1e-3).has_value());
  MatrixX3d points(3, 3);
  points << 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 0.5, 3.0, 0.5;
  try {
    locate_points(locator, points, 1e-6, "output.probes");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("output.probes.2: point (0.5, 3, 0.5) lies "
                                                   "outside the mesh"));
  }
  const std::vector<TetLocation> found = locate_points(locator, points.topRows(2), 1e-6, "probes");
  ASSERT_EQ(found.size(), 2u);
}

TEST(PointLocation, NonConvexMeshHoleIsOutside) {
  // An L-shaped mesh from two boxes: the notch of the L is outside although inside the grid's box.
  const TetMesh a = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), {2, 1, 1});
  TetMesh mesh;
  mesh.vertices.resize(2 * a.vertices.rows(), 3);
  mesh.vertices << a.vertices, a.vertices;
  mesh.vertices.bottomRows(a.vertices.rows()).col(1).array() += 1.0;
  mesh.vertices.bottomRows(a.vertices.rows()).col(0).array() *= 0.5;  // x in [0, 1]
  mesh.tets.resize(2 * a.tets.rows(), 4);
  mesh.tets << a.tets, (a.tets.array() + static_cast<int>(a.vertices.rows())).matrix();
  const TetLocator locator(mesh.vertices, mesh.tets);
  EXPECT_TRUE(locator.locate(Vector3d(0.5, 1.5, 0.5), 0.0).has_value());
  EXPECT_FALSE(locator.locate(Vector3d(1.5, 1.5, 0.5), 1e-3).has_value());
  const std::optional<TetLocation> near = locator.locate(Vector3d(1.01, 1.5, 0.5), 0.02);
  ASSERT_TRUE(near.has_value());
  EXPECT_NEAR(near->distance, 0.01, 1e-12);
}

}  // namespace
}  // namespace strata
