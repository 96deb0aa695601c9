#pragma once
/// \file mesh_surface_file.hpp
/// The whole path from a surface file to a simulation-ready tet mesh, as `strata mesh` and scenes
/// with "mesh": {"surface": ...} use it: read → check → (cache) → Mesh_3 → report.
#include <filesystem>
#include <string>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/mesh_cache.hpp"
#include "strata/meshing/meshing_options.hpp"
#include "strata/meshing/meshing_report.hpp"

namespace strata {

/// A generated mesh with what was found on the way.
struct SurfaceMeshingResult {
  TetMesh mesh;           ///< valid, positively oriented, no unused vertex
  SurfaceReport surface;  ///< the input as read
  MeshingReport report;   ///< route, time, cache use, quality, volume ratio
  std::string warning;    ///< one line when the surface was not watertight; else empty
  std::string cache_key;  ///< meshing_cache_key of the request
};

/// Reads `file` (read_surface), drops degenerate triangles and tetrahedralises it. A closed,
/// edge-manifold surface goes to the polyhedral domain (tetrahedralize_surface). Any other
/// surface (holes, non-manifold or misoriented edges) goes, with a warning, through a level set:
/// surface_to_level_set with voxels of facet_size / 4 (signs by winding number), then
/// tetrahedralize_implicit. With a cache, a request with the same file content, options and
/// route is loaded instead of meshed, and new meshes are stored. The tet-count guard
/// (check_meshing_request) uses the surface's enclosed volume. InputErrors name the file.
SurfaceMeshingResult mesh_surface_file(const std::filesystem::path& file,
                                       const MeshingOptions& options,
                                       const MeshCache* cache = nullptr);

/// Voxel size of the level-set route: resolved facet_size / kLevelSetVoxelsPerFacet.
inline constexpr double kLevelSetVoxelsPerFacet = 4.0;

}  // namespace strata
