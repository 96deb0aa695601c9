#pragma once
// Shared helpers for the meshing tests: procedural surfaces and random points.
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

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

/// The unit sphere as an icosahedron whose triangles are split into four `subdivisions` times, the
/// new vertices pushed onto the sphere: 10·4^n + 2 vertices, counter-clockwise seen from outside.
inline SurfaceMesh sphere_surface(int subdivisions) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3d> points = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                  {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                  {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vector3d& p : points)
    p.normalize();
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int a, int b) {
      const auto [slot, inserted] =
          midpoints.emplace(std::minmax(a, b), static_cast<int>(points.size()));
      if (inserted) points.push_back((points[a] + points[b]).normalized());
      return slot->second;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& [a, b, c] : faces) {
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  SurfaceMesh surface;
  surface.vertices.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v)
    surface.vertices.row(static_cast<Index>(v)) = points[v].transpose();
  surface.triangles.resize(static_cast<Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    surface.triangles.row(static_cast<Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
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
