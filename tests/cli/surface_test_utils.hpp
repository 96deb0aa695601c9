#pragma once
// Helpers for CLI tests with a fine surface: a watertight bar surface as OFF text and the points
// of a .vtp written by strata.
#include <array>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_utils.hpp"
#include "strata/core/common/types.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata::cli_test {

/// The surface of the bar [0, 1] × [0, 0.2] × [0, 0.2], each face an n × m grid of quads split
/// into triangles (outward, counter-clockwise, watertight), as OFF text; also returns the
/// vertices.
inline std::string bar_off(MatrixX3d& vertices) {
  std::vector<Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
  const Vector3d size(1.0, 0.2, 0.2);
  const int cells[3] = {20, 4, 4};
  std::map<std::array<int, 3>, int> index;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      std::vector<int> grid;  // vertex of grid point (i, j); seams share vertices
      for (int j = 0; j <= cells[v]; ++j)
        for (int i = 0; i <= cells[u]; ++i) {
          std::array<int, 3> key;
          key[axis] = side * cells[axis];
          key[u] = i;
          key[v] = j;
          const auto [slot, inserted] = index.emplace(key, static_cast<int>(points.size()));
          if (inserted)
            points.push_back(Vector3d(size(0) * key[0] / cells[0], size(1) * key[1] / cells[1],
                                      size(2) * key[2] / cells[2]));
          grid.push_back(slot->second);
        }
      const auto id = [&](int i, int j) { return grid[j * (cells[u] + 1) + i]; };
      for (int j = 0; j < cells[v]; ++j)
        for (int i = 0; i < cells[u]; ++i) {
          // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
          std::array<int, 3> t0{id(i, j), id(i + 1, j), id(i + 1, j + 1)};
          std::array<int, 3> t1{id(i, j), id(i + 1, j + 1), id(i, j + 1)};
          if (side == 0) {
            std::swap(t0[1], t0[2]);
            std::swap(t1[1], t1[2]);
          }
          triangles.push_back(t0);
          triangles.push_back(t1);
        }
    }
  }
  std::ostringstream off;
  off << "OFF\n" << points.size() << ' ' << triangles.size() << " 0\n";
  off.precision(17);
  vertices.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t k = 0; k < points.size(); ++k) {
    off << points[k](0) << ' ' << points[k](1) << ' ' << points[k](2) << '\n';
    vertices.row(static_cast<Index>(k)) = points[k].transpose();
  }
  for (const auto& t : triangles)
    off << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  return off.str();
}

/// The points of a .vtp frame written by strata (either encoding).
inline MatrixX3d read_vtp_points(const std::filesystem::path& path) {
  return read_vtk_frame(path).points;
}

/// Checks a deformed surface frame against the volume frame it belongs to: every surface vertex
/// inside the rest tet mesh equals the barycentric interpolation of the deformed volume (computed
/// here with the core's point locator), at least a quarter of the vertices are inside, and no
/// vertex moved more than 1.5 × the volume's largest displacement (outside ones extrapolate).
inline void expect_surface_follows_volume(const MatrixX3d& surface_rest,
                                          const MatrixX3d& surface_deformed, const TetMesh& rest,
                                          const TetMesh& deformed) {
  ASSERT_EQ(deformed.vertices.rows(), rest.vertices.rows());
  ASSERT_EQ(surface_deformed.rows(), surface_rest.rows());
  const double sag = (deformed.vertices - rest.vertices).rowwise().norm().maxCoeff();
  EXPECT_GT(sag, 1e-4);
  const TetLocator locator(rest.vertices, rest.tets);
  Index inside = 0;
  for (Index i = 0; i < surface_rest.rows(); ++i) {
    const std::optional<TetLocation> location =
        locator.locate(surface_rest.row(i).transpose(), 0.0);
    if (!location || location->distance > 0.0) continue;
    ++inside;
    Vector3d expected = Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      expected +=
          location->barycentric(k) * deformed.vertices.row(rest.tets(location->tet, k)).transpose();
    EXPECT_LT((surface_deformed.row(i).transpose() - expected).norm(), 1e-12) << "vertex " << i;
  }
  EXPECT_GT(inside, surface_rest.rows() / 4);
  EXPECT_LT((surface_deformed - surface_rest).rowwise().norm().maxCoeff(), 1.5 * sag);
}

}  // namespace strata::cli_test
