#pragma once
/// \file surface_simplification.hpp
/// Fewer vertices for the same closed surface: CGAL's edge-collapse simplification with the
/// Lindstrom–Turk cost and placement (each collapse keeps the enclosed volume and the boundary to
/// first order, "Fast and memory efficient polygonal simplification", 1998).
#include <string>

#include "strata/core/common/types.hpp"
#include "strata/meshing/surface_mesh.hpp"

namespace strata {

/// The surface collapsed to `target_vertices` vertices (CGAL stops on the edge count: exactly the
/// target for a connected genus-0 surface, about it for others), orientation kept, vertices
/// renumbered densely. A surface already at or below the target is returned unchanged. Throws
/// InputError naming `where` for a target below 4, a surface that is not a closed 2-manifold, or a
/// failed collapse.
SurfaceMesh simplify_surface(const SurfaceMesh& surface, Index target_vertices,
                             const std::string& where);

}  // namespace strata
