#pragma once
/// \file surface_mesh.hpp
/// A triangle surface mesh as plain arrays; enclosed volume and removal of degenerate triangles.
#include "strata/core/common/types.hpp"

namespace strata {

struct SurfaceMesh {
  MatrixX3d vertices;   ///< #V × 3 [m]
  MatrixX3i triangles;  ///< #F × 3, counter-clockwise seen from outside
};

/// Volume enclosed by a closed, outward-oriented surface (divergence theorem): Σ x0·(x1×x2)/6.
double enclosed_volume(const SurfaceMesh& surface);

/// True when the triangle has a repeated vertex index or zero area
/// (|(x1−x0)×(x2−x0)| ≤ 1e-14 · (longest edge)²).
bool is_degenerate_triangle(const SurfaceMesh& surface, Index triangle);

/// Removes degenerate triangles (is_degenerate_triangle) and then vertices no triangle uses,
/// renumbering the rest; returns the number of triangles removed.
Index remove_degenerate_triangles(SurfaceMesh& surface);

}  // namespace strata
