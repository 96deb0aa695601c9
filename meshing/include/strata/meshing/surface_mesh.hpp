#pragma once
/// \file surface_mesh.hpp
/// A triangle surface mesh as plain arrays (the Meshing issue adds readers, level sets and Mesh_3).
#include "strata/core/common/types.hpp"

namespace strata {

struct SurfaceMesh {
  MatrixX3d vertices;   ///< #V × 3 [m]
  MatrixX3i triangles;  ///< #F × 3, counter-clockwise seen from outside
};

/// Volume enclosed by a closed, outward-oriented surface (divergence theorem): Σ x0·(x1×x2)/6.
double enclosed_volume(const SurfaceMesh& surface);

}  // namespace strata
