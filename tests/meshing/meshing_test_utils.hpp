#pragma once
// Shared helpers for the meshing tests: procedural surfaces and random points.
#include <random>

#include "strata/meshing/surface_mesh.hpp"

namespace strata::testing {

/// The closed surface of the box [lo, hi]: 8 vertices, 12 triangles, counter-clockwise seen from
/// outside. Faces in order −x, +x, −y, +y, −z, +z (two triangles each).
inline SurfaceMesh box_surface(const Vector3d& lo, const Vector3d& hi) {
  SurfaceMesh surface;
  surface.vertices.resize(8, 3);
  for (int v = 0; v < 8; ++v)
    surface.vertices.row(v) << (v & 1 ? hi(0) : lo(0)), (v & 2 ? hi(1) : lo(1)),
        (v & 4 ? hi(2) : lo(2));
  surface.triangles.resize(12, 3);
  surface.triangles << 0, 4, 6, 0, 6, 2,  // −x
      1, 3, 7, 1, 7, 5,                   // +x
      0, 1, 5, 0, 5, 4,                   // −y
      2, 6, 7, 2, 7, 3,                   // +y
      0, 2, 3, 0, 3, 1,                   // −z
      4, 5, 7, 4, 7, 6;                   // +z
  return surface;
}

/// Uniform random point in the box [lo, hi].
inline Vector3d random_point(std::mt19937& rng, const Vector3d& lo, const Vector3d& hi) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return lo + Vector3d(unit(rng), unit(rng), unit(rng)).cwiseProduct(hi - lo);
}

/// Uniform random unit vector.
inline Vector3d random_direction(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

}  // namespace strata::testing
