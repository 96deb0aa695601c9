#include "strata/meshing/surface_mesh.hpp"

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
