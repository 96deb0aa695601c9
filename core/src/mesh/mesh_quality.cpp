#include "strata/core/mesh/mesh_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

namespace strata {
namespace {

constexpr double kDegrees = 180.0 / std::numbers::pi;

/// Faces used once, counted by sorting the sorted vertex triples of all tet faces.
Index count_boundary_faces(const MatrixX4i& tets) {
  std::vector<std::array<int, 3>> faces;
  faces.reserve(4 * tets.rows());
  for (Index t = 0; t < tets.rows(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> face;
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) face[n++] = tets(t, k);
      std::sort(face.begin(), face.end());
      faces.push_back(face);
    }
  std::sort(faces.begin(), faces.end());
  Index boundary = 0;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j] == faces[i])
      ++j;
    if (j - i == 1) ++boundary;
    i = j;
  }
  return boundary;
}

}  // namespace

double tet_dihedral_angle(const Matrix3x4d& x, int a, int b) {
  int others[2];
  int n = 0;
  for (int k = 0; k < 4; ++k)
    if (k != a && k != b) others[n++] = k;
  const Vector3d edge = x.col(b) - x.col(a);
  // Normals of the two faces through the edge, both taken relative to the edge direction: the
  // angle between them is the dihedral angle.
  const Vector3d n0 = edge.cross(x.col(others[0]) - x.col(a));
  const Vector3d n1 = edge.cross(x.col(others[1]) - x.col(a));
  return std::atan2(n0.cross(n1).norm(), n0.dot(n1));
}

double tet_radius_ratio(const Matrix3x4d& x) {
  const Vector3d a = x.col(1) - x.col(0);
  const Vector3d b = x.col(2) - x.col(0);
  const Vector3d c = x.col(3) - x.col(0);
  const double six_volume = std::abs(a.dot(b.cross(c)));
  double area2 = 0.0;  // twice the surface area
  area2 += a.cross(b).norm() + b.cross(c).norm() + c.cross(a).norm();
  area2 += (b - a).cross(c - a).norm();
  // R = |a²(b×c) + b²(c×a) + c²(a×b)| / (12 V);  r = 3V / A;  3r/R = 108 V² / (A · |…|).
  const double numerator =
      (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b))
          .norm();
  if (six_volume == 0.0 || numerator == 0.0) return 0.0;
  const double volume = six_volume / 6.0;
  return 108.0 * volume * volume / (0.5 * area2 * numerator);
}

MeshQuality compute_mesh_quality(const TetMesh& mesh) {
  MeshQuality q;
  q.vertices = mesh.vertices.rows();
  q.tets = mesh.tets.rows();
  if (q.vertices > 0) {
    q.bbox_min = mesh.vertices.colwise().minCoeff().transpose();
    q.bbox_max = mesh.vertices.colwise().maxCoeff().transpose();
  }
  if (q.tets == 0) return q;
  q.boundary_faces = count_boundary_faces(mesh.tets);

  constexpr double kInf = std::numeric_limits<double>::infinity();
  q.min_tet_volume = q.min_edge_length = q.min_dihedral_angle = q.min_radius_ratio = kInf;
  q.max_tet_volume = q.max_edge_length = q.max_dihedral_angle = -kInf;
  double radius_ratio_sum = 0.0;
  constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (Index t = 0; t < q.tets; ++t) {
    Matrix3x4d x;
    for (int k = 0; k < 4; ++k)
      x.col(k) = mesh.vertices.row(mesh.tets(t, k)).transpose();
    const double volume = tet_signed_volume(x.col(0), x.col(1), x.col(2), x.col(3));
    q.total_volume += volume;
    q.min_tet_volume = std::min(q.min_tet_volume, volume);
    q.max_tet_volume = std::max(q.max_tet_volume, volume);
    if (volume < 0.0) ++q.negative_tets;
    for (const auto& edge : kEdges) {
      const double length = (x.col(edge[1]) - x.col(edge[0])).norm();
      q.min_edge_length = std::min(q.min_edge_length, length);
      q.max_edge_length = std::max(q.max_edge_length, length);
      const double angle = tet_dihedral_angle(x, edge[0], edge[1]) * kDegrees;
      q.min_dihedral_angle = std::min(q.min_dihedral_angle, angle);
      q.max_dihedral_angle = std::max(q.max_dihedral_angle, angle);
    }
    const double ratio = tet_radius_ratio(x);
    q.min_radius_ratio = std::min(q.min_radius_ratio, ratio);
    radius_ratio_sum += ratio;
  }
  q.mean_radius_ratio = radius_ratio_sum / static_cast<double>(q.tets);
  return q;
}

std::string format_mesh_quality(const MeshQuality& q) {
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "vertices          %lld\n"
                "tets              %lld\n"
                "boundary faces    %lld\n"
                "bounding box      [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]\n"
                "volume            %.6g (tet volume min %.6g, max %.6g)\n"
                "edge length       min %.6g, max %.6g\n"
                "dihedral angle    min %.3f deg, max %.3f deg\n"
                "radius ratio      min %.4f, mean %.4f (1 = regular tet)\n"
                "inverted tets     %lld\n",
                static_cast<long long>(q.vertices), static_cast<long long>(q.tets),
                static_cast<long long>(q.boundary_faces), q.bbox_min.x(), q.bbox_min.y(),
                q.bbox_min.z(), q.bbox_max.x(), q.bbox_max.y(), q.bbox_max.z(), q.total_volume,
                q.min_tet_volume, q.max_tet_volume, q.min_edge_length, q.max_edge_length,
                q.min_dihedral_angle, q.max_dihedral_angle, q.min_radius_ratio, q.mean_radius_ratio,
                static_cast<long long>(q.negative_tets));
  return buffer;
}

}  // namespace strata
