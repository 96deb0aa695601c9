#pragma once
/// \file mesh_level_set.hpp
/// Tet meshes of the inside (φ < 0) of a level set, as `strata mesh shape.vdb` and scenes with
/// "mesh": {"level_set": ...} or {"implicit": ...} use them: level set → (cache) → Mesh_3 → report.
#include <filesystem>
#include <string>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/implicit_shape.hpp"
#include "strata/meshing/level_set.hpp"
#include "strata/meshing/mesh_cache.hpp"
#include "strata/meshing/meshing_options.hpp"
#include "strata/meshing/meshing_report.hpp"

namespace strata {

/// Route name of level-set meshing in MeshingReport::route.
inline constexpr const char* kLevelSetRoute = "level set";

/// A mesh generated from a level set.
struct LevelSetMeshingResult {
  TetMesh mesh;  ///< valid, positively oriented, no unused vertex
  /// route "level set"; surface_volume = level_set_volume of the input (the reference of the
  /// volume ratio).
  MeshingReport report;
  std::string cache_key;  ///< meshing_cache_key(_of_bytes) of the request
};

/// Volume [m³] enclosed by the zero iso-surface of `level_set` (LevelSet::to_surface, then
/// |Σ x0·(x1×x2)/6|): a voxel-resolution estimate of the volume of { φ < 0 }, independent of
/// Mesh_3. Zero for an empty level set.
double level_set_volume(const LevelSet& level_set);

/// Tetrahedralises { φ < 0 } with Mesh_3's implicit domain (tetrahedralize_implicit) over the
/// bounding box of the active voxels grown by 2 voxels (φ > 0 on its faces). The tet-count guard
/// uses `volume_estimate` [m³] (0: the box volume). InputError when φ is not positive at the box's
/// corners (an inverted or unbounded grid), or as tetrahedralize_implicit.
TetMesh tetrahedralize_level_set(const LevelSet& level_set, const MeshingOptions& options,
                                 double volume_estimate = 0.0);

/// Meshes a level set whose identity for the cache is `cache_bytes` (+ options + route): checks
/// that it encloses a volume and the tet-count guard (check_meshing_request with
/// level_set_volume), then loads the mesh from `cache` or meshes and stores it. InputError when
/// the level set encloses no volume or the request is refused.
LevelSetMeshingResult mesh_level_set(const LevelSet& level_set, const MeshingOptions& options,
                                     const std::string& cache_bytes,
                                     const MeshCache* cache = nullptr);

/// Reads the float grid `grid_name` ("" → the first float grid) of the .vdb `file` and meshes it
/// (mesh_level_set; cache key: the file's bytes, the grid name and the options). InputErrors name
/// the file (and grid).
LevelSetMeshingResult mesh_level_set_file(const std::filesystem::path& file,
                                          const std::string& grid_name,
                                          const MeshingOptions& options,
                                          const MeshCache* cache = nullptr);

/// Builds the shape's level set on voxels of `voxel_size` (0 → implicit_voxel_size(options)) and
/// meshes it (mesh_level_set; cache key: describe_implicit_shape, the voxel size and the
/// options). InputError for a bad shape or voxel size, or as mesh_level_set.
LevelSetMeshingResult mesh_implicit_shape(const ImplicitShape& shape, double voxel_size,
                                          const MeshingOptions& options,
                                          const MeshCache* cache = nullptr);

/// Default voxel size of implicit shapes: resolved facet_size (cell_size when unset) /
/// kLevelSetVoxelsPerFacet (4), as the level-set route of surfaces.
double implicit_voxel_size(const MeshingOptions& options);

/// True for the extension ".vdb" (any case).
bool is_vdb_file(const std::filesystem::path& path);

/// Multi-line report of a level set, one quantity per line (as `strata info shape.vdb` prints):
/// grid name, voxel size, background, bounding box of the active voxels, active voxel count and
/// level_set_volume.
std::string format_level_set_report(const LevelSet& level_set);

}  // namespace strata
