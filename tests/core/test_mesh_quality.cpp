// Mesh quality statistics against analytic values and independent formulas.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Dense>

#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

TetMesh regular_tet() {
  TetMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  mesh.tets.resize(1, 4);
  mesh.tets << 0, 1, 2, 3;
  if (mesh_volume(mesh) < 0) std::swap(mesh.tets(0, 2), mesh.tets(0, 3));
  return mesh;
}

TEST(MeshQuality, RegularTet) {
  const MeshQuality q = compute_mesh_quality(regular_tet());
  const double dihedral = std::acos(1.0 / 3.0) * kDeg;  // 70.5288°
  EXPECT_NEAR(dihedral, 70.5288, 1e-4);
  EXPECT_NEAR(q.min_dihedral_angle, dihedral, 1e-12);
  EXPECT_NEAR(q.max_dihedral_angle, dihedral, 1e-12);
  EXPECT_NEAR(q.min_radius_ratio, 1.0, 1e-14);
  EXPECT_NEAR(q.mean_radius_ratio, 1.0, 1e-14);
  EXPECT_NEAR(q.min_edge_length, 2 * std::sqrt(2.0), 1e-14);
  EXPECT_NEAR(q.max_edge_length, 2 * std::sqrt(2.0), 1e-14);
  // The tet is the cube [-1,1]³ minus four corner tets of volume 4/3: 8 − 16/3 = 8/3.
  EXPECT_NEAR(q.total_volume, 8.0 / 3.0, 1e-14);
  EXPECT_EQ(q.tets, 1);
  EXPECT_EQ(q.vertices, 4);
  EXPECT_EQ(q.boundary_faces, 4);
  EXPECT_EQ(q.negative_tets, 0);
}

TEST(MeshQuality, BoxMeshVolumeFacesAndEdges) {
  const TetMesh mesh = box_tet_mesh(Vector3d(-1, 0, 2), Vector3d(1, 1, 5), {2, 3, 4});
  const MeshQuality q = compute_mesh_quality(mesh);
  EXPECT_NEAR(q.total_volume, 2.0 * 1.0 * 3.0, 1e-13);
  EXPECT_NEAR(q.min_tet_volume, 6.0 / (6 * 24), 1e-15);  // all tets of a Kuhn split are equal
  EXPECT_NEAR(q.max_tet_volume, 6.0 / (6 * 24), 1e-15);
  EXPECT_EQ(q.tets, 6 * 24);
  EXPECT_EQ(q.vertices, 3 * 4 * 5);
  // Two triangles per boundary cell face.
  EXPECT_EQ(q.boundary_faces, 2 * 2 * (2 * 3 + 3 * 4 + 2 * 4));
  const Vector3d cell(1.0, 1.0 / 3.0, 0.75);
  EXPECT_NEAR(q.min_edge_length, 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(q.max_edge_length, cell.norm(), 1e-15);
  EXPECT_EQ(q.negative_tets, 0);
  EXPECT_TRUE(q.bbox_min.isApprox(Vector3d(-1, 0, 2)));
  EXPECT_TRUE(q.bbox_max.isApprox(Vector3d(1, 1, 5)));
}

TEST(MeshQuality, CubeKuhnTetAngles) {
  // A Kuhn tet of a cube has dihedral angles 45°, 60° and 90°.
  const MeshQuality q =
      compute_mesh_quality(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1}));
  EXPECT_NEAR(q.min_dihedral_angle, 45.0, 1e-12);
  EXPECT_NEAR(q.max_dihedral_angle, 90.0, 1e-12);
}

TEST(MeshQuality, InvertedTetIsCounted) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  std::swap(mesh.tets(2, 0), mesh.tets(2, 1));
  const MeshQuality q = compute_mesh_quality(mesh);
  EXPECT_EQ(q.negative_tets, 1);
  EXPECT_NEAR(q.min_tet_volume, -1.0 / 6.0, 1e-15);
  EXPECT_NEAR(q.total_volume, 4.0 / 6.0, 1e-15);
  EXPECT_EQ(q.boundary_faces, 12);
}

/// Independent formulas: dihedral angles from outward face normals (π − angle between them),
/// circumradius from solving for the circumcentre, inradius 3V / area.
TEST(MeshQuality, AnglesAndRadiusRatioMatchIndependentFormulas) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Matrix3x4d x;
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d)
        x(d, k) = coordinate(random);
    const Vector3d centroid = x.rowwise().mean();
    // Outward normal of the face opposite vertex k.
    auto outward_normal = [&](int k) {
      int f[3], n = 0;
      for (int j = 0; j < 4; ++j)
        if (j != k) f[n++] = j;
      Vector3d normal = (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0])).normalized();
      if (normal.dot(x.col(f[0]) - centroid) < 0) normal = -normal;
      return normal;
    };
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        int c = -1, d = -1;
        for (int j = 0; j < 4; ++j)
          if (j != a && j != b) (c < 0 ? c : d) = j;
        // The faces through edge (a, b) are those opposite c and d.
        const double expected =
            std::numbers::pi -
            std::acos(std::clamp(outward_normal(c).dot(outward_normal(d)), -1.0, 1.0));
        EXPECT_NEAR(tet_dihedral_angle(x, a, b), expected, 1e-7);
      }
    Matrix3d system;
    Vector3d rhs;
    for (int k = 1; k < 4; ++k) {
      system.row(k - 1) = 2 * (x.col(k) - x.col(0)).transpose();
      rhs[k - 1] = x.col(k).squaredNorm() - x.col(0).squaredNorm();
    }
    const Vector3d centre = system.fullPivLu().solve(rhs);
    const double circumradius = (centre - x.col(0)).norm();
    const double volume = std::abs(tet_signed_volume(x.col(0), x.col(1), x.col(2), x.col(3)));
    double area = 0;
    for (int k = 0; k < 4; ++k) {
      int f[3], n = 0;
      for (int j = 0; j < 4; ++j)
        if (j != k) f[n++] = j;
      area += 0.5 * (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0])).norm();
    }
    const double inradius = 3 * volume / area;
    EXPECT_NEAR(tet_radius_ratio(x), 3 * inradius / circumradius, 1e-9);
    EXPECT_LE(tet_radius_ratio(x), 1.0 + 1e-12);
  }
}

TEST(MeshQuality, DegenerateAndEmpty) {
  Matrix3x4d flat;
  flat << 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0;
  EXPECT_EQ(tet_radius_ratio(flat), 0.0);
  TetMesh empty;
  const MeshQuality q = compute_mesh_quality(empty);
  EXPECT_EQ(q.tets, 0);
  EXPECT_EQ(q.total_volume, 0.0);
  EXPECT_FALSE(format_mesh_quality(q).empty());
}

TEST(MeshQuality, ReportListsTheNumbers) {
  const std::string report = format_mesh_quality(compute_mesh_quality(regular_tet()));
  EXPECT_NE(report.find("tets              1\n"), std::string::npos) << report;
  EXPECT_NE(report.find("70.529"), std::string::npos) << report;
  EXPECT_NE(report.find("inverted tets     0"), std::string::npos) << report;
}

}  // namespace
}  // namespace strata
