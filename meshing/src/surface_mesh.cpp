#include "strata/meshing/surface_mesh.hpp"

#include <algorithm>
#include <vector>

namespace strata {

double enclosed_volume(const SurfaceMesh& surface) {
  double volume = 0.0;
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    const Vector3d x0 = surface.vertices.row(surface.triangles(f, 0)).transpose();
    const Vector3d x1 = surface.vertices.row(surface.triangles(f, 1)).transpose();
    const Vector3d x2 = surface.vertices.row(surface.triangles(f, 2)).transpose();
    volume += x0.dot(x1.cross(x2)) / 6.0;
  }
  return volume;
}

}  // namespace strata

namespace strata {

bool is_degenerate_triangle(const SurfaceMesh& surface, Index triangle) {
  const int i0 = surface.triangles(triangle, 0);
  const int i1 = surface.triangles(triangle, 1);
  const int i2 = surface.triangles(triangle, 2);
  if (i0 == i1 || i1 == i2 || i0 == i2) return true;
  const Vector3d x0 = surface.vertices.row(i0).transpose();
  const Vector3d e1 = surface.vertices.row(i1).transpose() - x0;
  const Vector3d e2 = surface.vertices.row(i2).transpose() - x0;
  const double longest = std::max({e1.squaredNorm(), e2.squaredNorm(), (e2 - e1).squaredNorm()});
  return e1.cross(e2).norm() <= 1e-14 * longest;
}

Index remove_degenerate_triangles(SurfaceMesh& surface) {
  const Index num_triangles = surface.triangles.rows();
  MatrixX3i kept(num_triangles, 3);
  Index num_kept = 0;
  for (Index f = 0; f < num_triangles; ++f) {
    if (!is_degenerate_triangle(surface, f)) kept.row(num_kept++) = surface.triangles.row(f);
  }
  std::vector<int> new_index(static_cast<std::size_t>(surface.vertices.rows()), -1);
  int num_vertices = 0;
  for (Index f = 0; f < num_kept; ++f) {
    for (int k = 0; k < 3; ++k) {
      int& index = new_index[static_cast<std::size_t>(kept(f, k))];
      if (index < 0) index = num_vertices++;
      kept(f, k) = index;
    }
  }
  MatrixX3d vertices(num_vertices, 3);
  for (Index v = 0; v < surface.vertices.rows(); ++v) {
    if (new_index[static_cast<std::size_t>(v)] >= 0) {
      vertices.row(new_index[static_cast<std::size_t>(v)]) = surface.vertices.row(v);
    }
  }
  surface.vertices = std::move(vertices);
  surface.triangles = kept.topRows(num_kept);
  return num_triangles - num_kept;
}

}  // namespace strata
