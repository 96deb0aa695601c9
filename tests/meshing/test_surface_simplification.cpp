// Surface simplification (CGAL edge collapse) and the triangle-frame binding that lets a simplified
// surface carry the full one: a simplified sphere stays a closed, outward sphere of about its
// volume; the binding reproduces the rest surface, moves it rigidly under rigid motions and
// follows affine maps exactly on the coarse triangles.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "meshing_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/surface_simplification.hpp"
#include "strata/meshing/triangle_frame_binding.hpp"

namespace strata {
namespace {

using testing::sphere_surface;

/// Whether every directed edge appears once and its reverse once: a closed, consistently
/// oriented 2-manifold.
bool closed_and_oriented(const SurfaceMesh& surface) {
  std::map<std::pair<int, int>, int> directed;
  for (Index f = 0; f < surface.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      ++directed[{surface.triangles(f, k), surface.triangles(f, (k + 1) % 3)}];
  for (const auto& [edge, count] : directed) {
    if (count != 1) return false;
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || reverse->second != 1) return false;
  }
  return true;
}

VectorXd stacked(ConstRef<MatrixX3d> points) {
  VectorXd x(3 * points.rows());
  for (Index i = 0; i < points.rows(); ++i)
    x.segment<3>(3 * i) = points.row(i).transpose();
  return x;
}

TEST(SurfaceSimplification, ASphereStaysAClosedSphereOfItsVolume) {
  const SurfaceMesh sphere = sphere_surface(4);  // 2,562 vertices
  ASSERT_TRUE(closed_and_oriented(sphere));
  const SurfaceMesh coarse = simplify_surface(sphere, 300, "sphere");
  EXPECT_EQ(coarse.vertices.rows(), 300);
  EXPECT_EQ(coarse.triangles.rows(), 2 * coarse.vertices.rows() - 4);  // closed genus 0
  EXPECT_TRUE(closed_and_oriented(coarse));
  // Lindstrom–Turk keeps the enclosed volume. With its vertices on the sphere, a 300-vertex
  // surface would hold about 2 % less than the 2,562-vertex one (the 162- and 642-vertex
  // icospheres hold 3.4 % and 0.9 % less than the ball).
  EXPECT_NEAR(enclosed_volume(coarse) / enclosed_volume(sphere), 1.0, 1e-3);
  for (Index v = 0; v < coarse.vertices.rows(); ++v)
    EXPECT_NEAR(coarse.vertices.row(v).norm(), 1.0, 0.02) << "vertex " << v;
}

TEST(SurfaceSimplification, KeepsASurfaceAtItsTargetAndRefusesBadInput) {
  const SurfaceMesh sphere = sphere_surface(1);  // 42 vertices
  const SurfaceMesh same = simplify_surface(sphere, 42, "sphere");
  EXPECT_EQ(same.vertices, sphere.vertices);
  EXPECT_EQ(same.triangles, sphere.triangles);
  EXPECT_THROW(simplify_surface(sphere, 3, "sphere"), InputError);
  SurfaceMesh open = sphere;
  open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
  try {
    simplify_surface(open, 20, "open.off");
    FAIL() << "an open surface was simplified";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("open.off: the surface has holes"), std::string::npos);
  }
}

TEST(TriangleFrameBinding, ReproducesTheRestSurfaceAndMovesItRigidly) {
  const SurfaceMesh fine = sphere_surface(4);
  const SurfaceMesh coarse = simplify_surface(fine, 120, "sphere");
  const TriangleFrameBinding binding =
      bind_to_triangles(coarse.vertices, coarse.triangles, fine.vertices);
  ASSERT_EQ(binding.triangles.size(), fine.vertices.rows());
  EXPECT_GT(binding.distance.maxCoeff(), 1e-3);  // the fine vertices are off the coarse surface
  const MatrixX3d rest = deformed_points(binding, coarse.triangles, stacked(coarse.vertices));
  EXPECT_LT((rest - fine.vertices).cwiseAbs().maxCoeff(), 1e-13);
  // A rotation about a tilted axis and a translation.
  const Matrix3d rotation = Eigen::AngleAxisd(1.1, Vector3d(1, -2, 0.5).normalized()).matrix();
  const Vector3d shift(0.3, -4.0, 2.5);
  const MatrixX3d moved_coarse =
      (coarse.vertices * rotation.transpose()).rowwise() + shift.transpose();
  const MatrixX3d moved = deformed_points(binding, coarse.triangles, stacked(moved_coarse));
  const MatrixX3d expected = (fine.vertices * rotation.transpose()).rowwise() + shift.transpose();
  EXPECT_LT((moved - expected).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(TriangleFrameBinding, PointsOnTheTrianglesFollowAffineMapsExactly) {
  const SurfaceMesh coarse = sphere_surface(2);
  // One point inside each triangle (off-centre barycentric coordinates).
  MatrixX3d points(coarse.triangles.rows(), 3);
  for (Index f = 0; f < coarse.triangles.rows(); ++f)
    points.row(f) = 0.5 * coarse.vertices.row(coarse.triangles(f, 0)) +
                    0.3 * coarse.vertices.row(coarse.triangles(f, 1)) +
                    0.2 * coarse.vertices.row(coarse.triangles(f, 2));
  const TriangleFrameBinding binding = bind_to_triangles(coarse.vertices, coarse.triangles, points);
  for (Index f = 0; f < points.rows(); ++f) {
    EXPECT_EQ(binding.triangles[f], f);
    EXPECT_LT(binding.offset.row(f).norm(), 1e-14);
    EXPECT_NEAR(binding.barycentric(f, 1), 0.3, 1e-12);
  }
  Matrix3d stretch;
  stretch << 1.4, 0.2, 0.0, -0.1, 0.7, 0.3, 0.05, 0.0, 1.9;
  const MatrixX3d mapped =
      deformed_points(binding, coarse.triangles, stacked(coarse.vertices * stretch.transpose()));
  EXPECT_LT((mapped - points * stretch.transpose()).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(TriangleFrameBinding, VelocitiesAreTheDerivativeOfThePoints) {
  const SurfaceMesh fine = sphere_surface(3);
  const SurfaceMesh coarse = simplify_surface(fine, 80, "sphere");
  const TriangleFrameBinding binding =
      bind_to_triangles(coarse.vertices, coarse.triangles, fine.vertices);
  // A non-affine state (bent and twisted) and a non-affine velocity field.
  const Index V = coarse.vertices.rows();
  VectorXd x(3 * V), v(3 * V);
  for (Index i = 0; i < V; ++i) {
    const Vector3d X = coarse.vertices.row(i).transpose();
    x.segment<3>(3 * i) = Vector3d(X.x() + 0.2 * std::sin(2.0 * X.z()), X.y() * (1.0 + 0.3 * X.x()),
                                   X.z() + 0.1 * X.x() * X.y());
    v.segment<3>(3 * i) = Vector3d(std::cos(3.0 * X.y()), X.x() * X.z(), 0.5 - X.y() * X.y());
  }
  const double h = 1e-6;
  const MatrixX3d difference = (deformed_points(binding, coarse.triangles, x + h * v) -
                                deformed_points(binding, coarse.triangles, x - h * v)) /
                               (2.0 * h);
  const MatrixX3d velocity = deformed_velocities(binding, coarse.triangles, x, v);
  ASSERT_EQ(velocity.rows(), fine.vertices.rows());
  EXPECT_GT(velocity.cwiseAbs().maxCoeff(), 0.5);
  EXPECT_LT((velocity - difference).cwiseAbs().maxCoeff(), 1e-7);
  // The offset's rotation counts: linear interpolation of the corners' velocities alone misses it.
  MatrixX3d interpolated(fine.vertices.rows(), 3);
  for (Index i = 0; i < interpolated.rows(); ++i) {
    Vector3d sum = Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      sum +=
          binding.barycentric(i, k) * v.segment<3>(3 * coarse.triangles(binding.triangles[i], k));
    interpolated.row(i) = sum.transpose();
  }
  EXPECT_GT((interpolated - difference).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(TriangleFrameBinding, RefusesNonFiniteVerticesAndBadIndices) {
  const SurfaceMesh coarse = sphere_surface(1);
  MatrixX3d fine = coarse.vertices;
  fine(3, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    bind_to_triangles(coarse.vertices, coarse.triangles, fine);
    FAIL() << "a NaN vertex was bound";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("fine surface vertex 3"), std::string::npos);
  }
  MatrixX3i triangles = coarse.triangles;
  triangles(5, 2) = 1000;
  EXPECT_THROW(bind_to_triangles(coarse.vertices, triangles, coarse.vertices), InputError);
}

}  // namespace
}  // namespace strata
