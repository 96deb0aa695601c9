#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/amplitude.hpp"
#include "strata/core/sim/loads.hpp"

namespace strata {
namespace {

TEST(SimLoads, TractionSharesFollowTriangleAreas) {
  // Non-uniform cells on the loaded face x = 1: y spacing 0.2 / 0.8 via a graded mesh.
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {1, 2, 1});
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    if (std::abs(mesh.vertices(v, 1) - 0.5) < 1e-12) mesh.vertices(v, 1) = 0.2;
  const MatrixX3i boundary = boundary_faces(mesh.tets);
  const double tol = region_tolerance(mesh.vertices);
  const std::vector<int> face =
      select_vertices(BoxRegion{Vector3d(1, -1, -1), Vector3d(1, 2, 2)}, mesh.vertices, tol);
  ASSERT_EQ(face.size(), 6u);
  VectorXd f = VectorXd::Zero(3 * mesh.vertices.rows());
  const Vector3d total(3.0, -1.0, 2.0);
  add_region_force("loads[0]", face, total, mesh.vertices, boundary, f);
  Vector3d sum = Vector3d::Zero();
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    sum += f.segment<3>(3 * v);
  EXPECT_LT((sum - total).norm(), 1e-14);
  // Independent computation: the face is the rectangle y ∈ [0,1], z ∈ [0,1] cut at y = 0.2 into
  // strips of area 0.2 and 0.8, each split into two triangles of equal area. Corner vertex
  // (y=0, z=0) touches triangles of the 0.2 strip only; which triangles depends on the diagonal,
  // so compare the strip totals: vertices with y = 0 receive only strip-0.2 shares.
  double y0_share = 0.0, y1_share = 0.0, mid_share = 0.0;
  for (int v : face) {
    const double share = f.segment<3>(3 * v).dot(total) / total.squaredNorm();
    if (mesh.vertices(v, 1) < 0.1)
      y0_share += share;
    else if (mesh.vertices(v, 1) > 0.9)
      y1_share += share;
    else
      mid_share += share;
  }
  // Each strip gives 1/3 of its load to each of its triangle corners: strip A (area fraction 0.2)
  // has corners at y = 0 (3 of 6 corner slots across its two triangles) and y = 0.2 (3 slots).
  EXPECT_NEAR(y0_share, 0.2 * 0.5, 1e-14);
  EXPECT_NEAR(y1_share, 0.8 * 0.5, 1e-14);
  EXPECT_NEAR(mid_share, 0.5, 1e-14);
}

TEST(SimLoads, RegionWithoutBoundaryTriangleSplitsEqually) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {1, 1, 1});
  const MatrixX3i boundary = boundary_faces(mesh.tets);
  // An edge of the cube: two vertices, no triangle.
  const std::vector<int> edge =
      select_vertices(BoxRegion{Vector3d(1, 1, 0), Vector3d(1, 1, 1)}, mesh.vertices, 1e-12);
  ASSERT_EQ(edge.size(), 2u);
  VectorXd f = VectorXd::Zero(3 * mesh.vertices.rows());
  add_region_force("loads[0]", edge, Vector3d(0, 0, -4), mesh.vertices, boundary, f);
  for (int v : edge)
    EXPECT_TRUE(f.segment<3>(3 * v).isApprox(Vector3d(0, 0, -2)));
  EXPECT_NEAR(f.sum(), -4.0, 1e-14);
  EXPECT_THROW(add_region_force("loads[3]", {}, Vector3d(1, 0, 0), mesh.vertices, boundary, f),
               InputError);
}

TEST(SimLoads, GravityAndEmptyRegionError) {
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {1, 1, 1});
  const MatrixX3i boundary = boundary_faces(mesh.tets);
  const VectorXd mass = VectorXd::LinSpaced(mesh.vertices.rows(), 1.0, 8.0);
  const VectorXd f =
      external_forces(mesh.vertices, boundary, mass, Vector3d(0, 0, -9.81), {}, 1e-12);
  for (Index v = 0; v < mass.size(); ++v)
    EXPECT_TRUE(f.segment<3>(3 * v).isApprox(Vector3d(0, 0, -9.81 * mass[v])));
  RegionLoad load{"loads[2]", BoxRegion{Vector3d(5, 5, 5), Vector3d(6, 6, 6)}, Vector3d(1, 0, 0)};
  try {
    external_forces(mesh.vertices, boundary, mass, Vector3d::Zero(), {load}, 1e-12);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "loads[2]: region selects no vertex");
  }
}

TEST(SimLoads, AmplitudePeakOverAnIntervalIsTheLargestMagnitudeInIt) {
  // Piecewise linear: the largest magnitude over [t0, t1] is at an end or at a table point
  // between them. Checked against dense samples: never below them, and above by at most the
  // steepest slope (100 /s) times the sample spacing.
  Amplitude amplitude;
  amplitude.points = {{0.0, 0.0}, {0.02, 1.0}, {0.05, -2.0}, {0.08, 0.5}};
  for (const auto& [t0, t1] : std::vector<std::pair<double, double>>{
           {0.0, 0.01}, {0.0, 0.03}, {0.03, 0.04}, {0.01, 0.07}, {0.06, 0.2}, {-1.0, 0.0}}) {
    constexpr int kSamples = 10000;
    double sampled = 0.0;
    for (int k = 0; k <= kSamples; ++k)
      sampled = std::max(sampled, std::abs(amplitude.value(t0 + (t1 - t0) * k / kSamples)));
    const double peak = amplitude.peak(t0, t1);
    EXPECT_GE(peak, sampled - 1e-15) << t0 << " " << t1;
    EXPECT_LE(peak - sampled, 100.0 * (t1 - t0) / kSamples + 1e-15) << t0 << " " << t1;
  }
  EXPECT_EQ(amplitude.peak(0.0, 1.0), amplitude.peak());
}

}  // namespace
}  // namespace strata
