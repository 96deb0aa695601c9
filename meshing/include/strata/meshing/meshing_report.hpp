#pragma once
/// \file meshing_report.hpp
/// What `strata info` and stats.json report about a surface and a generated tet mesh.
#include <string>

#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/meshing/surface_mesh.hpp"
#include "strata/meshing/surface_topology.hpp"

namespace strata {

/// Counts and defects of a triangle surface.
struct SurfaceReport {
  Index vertices = 0;
  Index triangles = 0;
  SurfaceTopology topology;  ///< boundary / non-manifold / misoriented edges, degenerate triangles
  /// Closed: every edge shared by exactly two triangles (no boundary or non-manifold edge).
  bool closed = false;
  double enclosed_volume = 0.0;  ///< |Σ x0·(x1×x2)/6| [m³]; meaningful when closed
  Vector3d bbox_min = Vector3d::Zero();
  Vector3d bbox_max = Vector3d::Zero();
};

SurfaceReport describe_surface(const SurfaceMesh& surface);

/// Multi-line report, one quantity per line (as printed by `strata info` for a surface file).
std::string format_surface_report(const SurfaceReport& report);

/// Quality of a generated tet mesh against the surface it came from.
struct MeshingReport {
  MeshQuality quality;          ///< tet count, dihedral angles, radius ratios, volume
  double surface_volume = 0.0;  ///< enclosed volume of the input surface [m³]; 0 when unknown
  std::string route;            ///< "polyhedral" or "level set"
  bool from_cache = false;      ///< loaded from the mesh cache instead of meshed
  double seconds = 0.0;         ///< meshing wall time [s] (0 when from the cache)

  /// Tet-mesh volume / surface volume (0 when the surface volume is unknown).
  double volume_ratio() const {
    return surface_volume > 0.0 ? quality.total_volume / surface_volume : 0.0;
  }
};

/// Multi-line report: the route, cache use, time and volume ratio, then format_mesh_quality.
std::string format_meshing_report(const MeshingReport& report);

}  // namespace strata
