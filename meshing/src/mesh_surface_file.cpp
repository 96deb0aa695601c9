#include "strata/meshing/mesh_surface_file.hpp"

#include <chrono>

#include "strata/core/common/error.hpp"
#include "strata/meshing/level_set.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/tetrahedralize.hpp"
#include "tetrahedralize_detail.hpp"

namespace strata {
namespace {

/// The level-set route: narrow band around the surface, Mesh_3 on its zero set.
TetMesh tetrahedralize_through_level_set(const SurfaceMesh& surface, const MeshingOptions& options,
                                         double volume_estimate) {
  LevelSetOptions level_set_options;
  level_set_options.voxel_size =
      detail::resolved_meshing_options(options).facet_size / kLevelSetVoxelsPerFacet;
  const SurfaceLevelSet level_set = surface_to_level_set(surface, level_set_options);
  auto [lo, hi] = level_set.level_set.bounding_box();
  const Vector3d margin = Vector3d::Constant(2.0 * level_set_options.voxel_size);
  const LevelSet& grid = level_set.level_set;
  return tetrahedralize_implicit([&grid](const Vector3d& p) { return grid.signed_distance(p); },
                                 lo - margin, hi + margin, options, volume_estimate);
}

}  // namespace

SurfaceMeshingResult mesh_surface_file(const std::filesystem::path& file,
                                       const MeshingOptions& options, const MeshCache* cache) {
  const std::string name = file.string();
  SurfaceMeshingResult result;
  SurfaceMesh surface = read_surface(file);
  result.surface = describe_surface(surface);
  remove_degenerate_triangles(surface);
  const bool closed_manifold = is_closed_manifold_surface(surface);
  const bool self_intersecting = closed_manifold && surface_self_intersects(surface);
  const bool polyhedral = closed_manifold && !self_intersecting;
  result.report.route = polyhedral ? "polyhedral" : "level set";
  if (self_intersecting) {
    result.warning = name + ": surface intersects itself: meshed through a level set";
  } else if (!polyhedral) {
    result.warning =
        name + ": surface " + result.surface.topology.summary() + ": meshed through a level set";
  }
  // An open surface encloses no volume: leave the ratio out of the report.
  if (result.surface.closed) result.report.surface_volume = result.surface.enclosed_volume;
  try {
    check_meshing_request(result.surface.enclosed_volume, options);
  } catch (const InputError& error) {
    throw InputError(name + ": " + error.what());
  }

  result.cache_key = meshing_cache_key(file, options, result.report.route);
  if (cache) {
    if (std::optional<TetMesh> cached = cache->load(result.cache_key)) {
      result.mesh = std::move(*cached);
      orient_tets(result.mesh);
      result.report.from_cache = true;
      result.report.quality = compute_mesh_quality(result.mesh);
      return result;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    result.mesh = polyhedral ? tetrahedralize_surface(surface, options)
                             : tetrahedralize_through_level_set(surface, options,
                                                                result.surface.enclosed_volume);
  } catch (const InputError& error) {
    throw InputError(name + ": " + error.what());
  }
  result.report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.report.quality = compute_mesh_quality(result.mesh);
  if (cache) cache->store(result.cache_key, result.mesh);
  return result;
}

}  // namespace strata
