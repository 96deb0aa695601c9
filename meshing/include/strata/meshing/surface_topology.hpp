#pragma once
/// \file surface_topology.hpp
/// Edge-based checks of a triangle surface: is it watertight (closed, edge-manifold, consistently
/// oriented)? Level sets and meshing report what they found on real, imperfect input.
#include <string>

#include "strata/meshing/surface_mesh.hpp"

namespace strata {

/// Counts of the defects of a triangle surface, by undirected edge.
struct SurfaceTopology {
  Index edges = 0;                 ///< distinct undirected edges
  Index boundary_edges = 0;        ///< edges used by one triangle (holes, open borders)
  Index non_manifold_edges = 0;    ///< edges used by three or more triangles
  Index misoriented_edges = 0;     ///< edges whose two triangles traverse it in the same direction
  Index degenerate_triangles = 0;  ///< triangles with a repeated vertex or zero area

  /// Closed, edge-manifold and consistently oriented (no counted defect).
  bool watertight() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && misoriented_edges == 0 &&
           degenerate_triangles == 0;
  }
  /// One line, e.g. "not watertight: 4 boundary edges, 0 non-manifold edges, ...".
  std::string summary() const;
};

/// Classifies every edge of `surface`. Triangle indices must be in range (InputError otherwise).
SurfaceTopology surface_topology(const SurfaceMesh& surface);

}  // namespace strata
