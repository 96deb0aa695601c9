// The fine surface bound to a tet mesh: reproduction at rest, rigid motion, nearest tets outside,
// and the displacement map against known offsets.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "meshing_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/meshing/surface_binding.hpp"

namespace strata {
namespace {

using testing::random_direction;
using testing::random_point;

/// A unit box mesh with jittered interior vertices (so tets are not all alike).
TetMesh jittered_box(const std::array<int, 3>& cells, unsigned seed) {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), cells);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d x = mesh.vertices.row(v).transpose();
    if ((x.array() > 1e-9).all() && (x.array() < 1 - 1e-9).all())
      for (int a = 0; a < 3; ++a)
        mesh.vertices(v, a) += jitter(rng) / cells[a];
  }
  return mesh;
}

/// An L-shaped mesh: the box with the tets of the quadrant x > ½, y > ½ removed (a notch).
TetMesh l_shaped_mesh() {
  const TetMesh box = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {4, 4, 2});
  TetMesh mesh;
  mesh.vertices = box.vertices;
  std::vector<Index> kept;
  for (Index t = 0; t < box.tets.rows(); ++t) {
    Vector3d centroid = Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      centroid += box.vertices.row(box.tets(t, k)).transpose() / 4.0;
    if (!(centroid(0) > 0.5 && centroid(1) > 0.5)) kept.push_back(t);
  }
  mesh.tets.resize(static_cast<Index>(kept.size()), 4);
  for (std::size_t i = 0; i < kept.size(); ++i)
    mesh.tets.row(i) = box.tets.row(kept[i]);
  return mesh;
}

double tet_distance(const TetMesh& mesh, Index t, const Vector3d& p) {
  return point_tet_distance(p, mesh.vertices.row(mesh.tets(t, 0)).transpose(),
                            mesh.vertices.row(mesh.tets(t, 1)).transpose(),
                            mesh.vertices.row(mesh.tets(t, 2)).transpose(),
                            mesh.vertices.row(mesh.tets(t, 3)).transpose());
}

/// Fine vertices: random points inside the unit box and within `outside` beyond its faces.
MatrixX3d fine_points(int inside, int outside, unsigned seed) {
  std::mt19937 rng(seed);
  MatrixX3d points(inside + outside, 3);
  for (int i = 0; i < inside; ++i)
    points.row(i) = random_point(rng, Vector3d(0, 0, 0), Vector3d(1, 1, 1)).transpose();
  for (int i = inside; i < inside + outside; ++i) {
    Vector3d p = random_point(rng, Vector3d(0, 0, 0), Vector3d(1, 1, 1));
    const int axis = i % 3;
    p(axis) = (i / 3) % 2 ? 1.0 + 0.05 * p(axis) : -0.05 * p(axis);
    points.row(i) = p.transpose();
  }
  return points;
}

Matrix3d random_rotation(std::mt19937& rng) {
  return Eigen::AngleAxisd(2.0, random_direction(rng)).toRotationMatrix();
}

TEST(SurfaceBinding, EveryVertexBoundAndRestReproduced) {
  const TetMesh mesh = jittered_box({4, 3, 5}, 1);
  const MatrixX3d fine = fine_points(2000, 300, 2);
  const SurfaceBinding binding = bind_surface(mesh, fine);
  ASSERT_EQ(binding.tets.size(), fine.rows());
  EXPECT_EQ(binding.num_outside, 300);
  for (Index i = 0; i < fine.rows(); ++i) {
    ASSERT_GE(binding.tets(i), 0);
    ASSERT_LT(binding.tets(i), mesh.tets.rows());
    EXPECT_EQ(binding.corners.row(i), mesh.tets.row(binding.tets(i)));
    EXPECT_NEAR(binding.barycentric.row(i).sum(), 1.0, 1e-12);
    if (i < 2000) {
      EXPECT_GE(binding.barycentric.row(i).minCoeff(), -1e-12);
      EXPECT_EQ(binding.distance(i), 0.0);
    }
  }
  const MatrixX3d rest = deformed_surface(binding, flatten(mesh.vertices));
  EXPECT_LT((rest - fine).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(SurfaceBinding, RigidMotionMovesTheSurfaceRigidly) {
  const TetMesh mesh = jittered_box({3, 3, 3}, 3);
  const MatrixX3d fine = fine_points(1000, 200, 4);
  const SurfaceBinding binding = bind_surface(mesh, fine);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 3; ++trial) {
    const Matrix3d rotation = random_rotation(rng);
    const Vector3d translation = 3.0 * random_direction(rng);
    MatrixX3d moved = mesh.vertices * rotation.transpose();
    moved.rowwise() += translation.transpose();
    MatrixX3d expected = fine * rotation.transpose();
    expected.rowwise() += translation.transpose();
    const MatrixX3d deformed = deformed_surface(binding, flatten(moved));
    EXPECT_LT((deformed - expected).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(SurfaceBinding, OutsideVerticesGetTheNearestTet) {
  for (const TetMesh& mesh : {jittered_box({3, 4, 2}, 6), l_shaped_mesh()}) {
    std::mt19937 rng(7);
    MatrixX3d points(300, 3);
    for (Index i = 0; i < points.rows(); ++i)  // around the box, in the notch of the L, inside
      points.row(i) =
          random_point(rng, Vector3d(-0.2, -0.2, -0.2), Vector3d(1.2, 1.2, 1.2)).transpose();
    const SurfaceBinding binding = bind_surface(mesh, points);
    for (Index i = 0; i < points.rows(); ++i) {
      const Vector3d p = points.row(i).transpose();
      double nearest = std::numeric_limits<double>::infinity();
      for (Index t = 0; t < mesh.tets.rows(); ++t)
        nearest = std::min(nearest, tet_distance(mesh, t, p));
      EXPECT_NEAR(binding.distance(i), nearest, 1e-12) << "vertex " << i;
      EXPECT_NEAR(tet_distance(mesh, binding.tets(i), p), nearest, 1e-12) << "vertex " << i;
      EXPECT_NEAR(binding.barycentric.row(i).sum(), 1.0, 1e-12);
    }
    const MatrixX3d rest = deformed_surface(binding, flatten(mesh.vertices));
    EXPECT_LT((rest - points).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(SurfaceBinding, TetBoundaryMatchesCoreBoundaryFaces) {
  TetMesh mesh = l_shaped_mesh();
  const TetBoundary boundary = tet_boundary(mesh);
  const MatrixX3i core_faces = boundary_faces(mesh.tets);
  ASSERT_EQ(boundary.faces.rows(), core_faces.rows());
  // The enclosed volume of the outward boundary equals the mesh volume (3/4 of the box).
  double volume = 0.0;
  for (Index f = 0; f < boundary.faces.rows(); ++f) {
    const Vector3d x0 = mesh.vertices.row(boundary.faces(f, 0)).transpose();
    const Vector3d x1 = mesh.vertices.row(boundary.faces(f, 1)).transpose();
    const Vector3d x2 = mesh.vertices.row(boundary.faces(f, 2)).transpose();
    volume += x0.dot(x1.cross(x2)) / 6.0;
    bool owned = false;
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c)
        owned |= mesh.tets(boundary.tets(f), k) == boundary.faces(f, c);
    EXPECT_TRUE(owned);
  }
  EXPECT_NEAR(volume, 0.75, 1e-12);
}

TEST(SurfaceBinding, DisplacementMapOfAnOffsetSurfaceIsTheOffset) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {3, 3, 3});
  std::mt19937 rng(8);
  std::vector<Vector3d> points;
  std::vector<double> expected;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const bool high = face % 2;
    for (int i = 0; i < 20; ++i) {
      // Outward by 0.07 anywhere over the face; inward by 0.05 away from the other faces.
      Vector3d p = random_point(rng, Vector3d(0.0, 0.0, 0.0), Vector3d(1, 1, 1));
      p(axis) = high ? 1.07 : -0.07;
      points.push_back(p);
      expected.push_back(0.07);
      Vector3d q = random_point(rng, Vector3d(0.2, 0.2, 0.2), Vector3d(0.8, 0.8, 0.8));
      q(axis) = high ? 0.95 : 0.05;
      points.push_back(q);
      expected.push_back(-0.05);
    }
  }
  MatrixX3d fine(static_cast<Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    fine.row(i) = points[i].transpose();
  const DisplacementMap map = displacement_map(mesh, fine);
  EXPECT_EQ(map.boundary_faces.rows(), 6 * 2 * 9);
  for (std::size_t i = 0; i < points.size(); ++i)
    EXPECT_NEAR(map.offset(i), expected[i], 1e-13) << "vertex " << i;
  // Coarse surface + map gives the points back, at rest and after a rigid motion.
  EXPECT_LT((displaced_surface(map, flatten(mesh.vertices)) - fine).cwiseAbs().maxCoeff(), 1e-13);
  const Matrix3d rotation = random_rotation(rng);
  MatrixX3d moved = mesh.vertices * rotation.transpose();
  MatrixX3d fine_moved = fine * rotation.transpose();
  EXPECT_LT((displaced_surface(map, flatten(moved)) - fine_moved).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(SurfaceBinding, HundredThousandVerticesAllBound) {
  // A 100k-vertex surface on a ~20k-tet mesh (the speed target); prints the time.
  const TetMesh mesh = jittered_box({15, 15, 15}, 9);
  const MatrixX3d fine = fine_points(95000, 5000, 10);
  const auto start = std::chrono::steady_clock::now();
  const SurfaceBinding binding = bind_surface(mesh, fine);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "[ measure  ] bind_surface: " << fine.rows() << " vertices on " << mesh.tets.rows()
            << " tets in " << seconds << " s\n";
  EXPECT_EQ(binding.num_outside, 5000);
  const MatrixX3d rest = deformed_surface(binding, flatten(mesh.vertices));
  EXPECT_LT((rest - fine).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(SurfaceBinding, BadInputIsRejected) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {1, 1, 1});
  MatrixX3d points = MatrixX3d::Zero(3, 3);
  points(1, 2) = std::nan("");
  EXPECT_THROW(bind_surface(mesh, points), InputError);
  EXPECT_THROW(bind_surface(TetMesh{}, MatrixX3d::Zero(1, 3)), InputError);
}

}  // namespace
}  // namespace strata
