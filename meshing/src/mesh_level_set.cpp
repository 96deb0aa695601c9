#include "strata/meshing/mesh_level_set.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "strata/core/common/error.hpp"
#include "strata/meshing/mesh_surface_file.hpp"
#include "strata/meshing/tetrahedralize.hpp"
#include "tetrahedralize_detail.hpp"

namespace strata {
namespace {

/// Margin of the meshing box around the active voxels [voxels].
constexpr double kBoxMarginVoxels = 2.0;

}  // namespace

double level_set_volume(const LevelSet& level_set) {
  if (level_set.num_active_voxels() == 0) return 0.0;
  const SurfaceMesh surface = level_set.to_surface();
  if (surface.triangles.rows() == 0) return 0.0;
  return std::abs(enclosed_volume(surface));
}

TetMesh tetrahedralize_level_set(const LevelSet& level_set, const MeshingOptions& options,
                                 double volume_estimate) {
  const auto [lo, hi] = level_set.bounding_box();
  const Vector3d margin = Vector3d::Constant(kBoxMarginVoxels * level_set.voxel_size());
  // Mesh_3 needs φ > 0 on the box: an inverted grid (negative outside) would mesh the box itself.
  for (int corner = 0; corner < 8; ++corner) {
    const Vector3d p((corner & 1 ? hi : lo).x(), (corner & 2 ? hi : lo).y(),
                     (corner & 4 ? hi : lo).z());
    if (!(level_set.signed_distance(p + (p - 0.5 * (lo + hi)).cwiseSign().cwiseProduct(margin)) >
          0.0)) {
      throw InputError("level set '" + level_set.name() +
                       "' is not positive outside its narrow band (an inverted or unbounded grid)");
    }
  }
  return tetrahedralize_implicit(
      [&level_set](const Vector3d& p) { return level_set.signed_distance(p); }, lo - margin,
      hi + margin, options, volume_estimate);
}

LevelSetMeshingResult mesh_level_set(const LevelSet& level_set, const MeshingOptions& options,
                                     const std::string& cache_bytes, const MeshCache* cache) {
  LevelSetMeshingResult result;
  result.report.route = kLevelSetRoute;
  result.report.surface_volume = level_set_volume(level_set);
  if (!(result.report.surface_volume > 0.0)) {
    throw InputError("level set '" + level_set.name() + "' encloses no volume");
  }
  check_meshing_request(result.report.surface_volume, options);

  result.cache_key = meshing_cache_key_of_bytes(cache_bytes, options, kLevelSetRoute);
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
  result.mesh = tetrahedralize_level_set(level_set, options, result.report.surface_volume);
  result.report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.report.quality = compute_mesh_quality(result.mesh);
  if (cache) cache->store(result.cache_key, result.mesh);
  return result;
}

LevelSetMeshingResult mesh_level_set_file(const std::filesystem::path& file,
                                          const std::string& grid_name,
                                          const MeshingOptions& options, const MeshCache* cache) {
  const LevelSet level_set = LevelSet::read_vdb(file, grid_name);
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) throw InputError(file.string() + ": cannot read");
  try {
    return mesh_level_set(level_set, options, "vdb|grid=" + grid_name + "|" + bytes.str(), cache);
  } catch (const InputError& error) {
    throw InputError(file.string() + ": " + error.what());
  }
}

LevelSetMeshingResult mesh_implicit_shape(const ImplicitShape& shape, double voxel_size,
                                          const MeshingOptions& options, const MeshCache* cache) {
  LevelSetOptions level_set_options;
  level_set_options.voxel_size = voxel_size > 0.0 ? voxel_size : implicit_voxel_size(options);
  const LevelSet level_set = implicit_shape_level_set(shape, level_set_options);
  std::ostringstream bytes;
  bytes.precision(17);
  bytes << "implicit|voxel=" << level_set_options.voxel_size
        << "|half_width=" << level_set_options.half_width << '|' << describe_implicit_shape(shape);
  return mesh_level_set(level_set, options, bytes.str(), cache);
}

double implicit_voxel_size(const MeshingOptions& options) {
  return detail::resolved_meshing_options(options).facet_size / kLevelSetVoxelsPerFacet;
}

bool is_vdb_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".vdb";
}

std::string format_level_set_report(const LevelSet& level_set) {
  const auto [lo, hi] = level_set.bounding_box();
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "grid              %s\n"
                "voxel size        %.6g\n"
                "background        %.6g\n"
                "bounding box      [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]\n"
                "active voxels     %lld\n"
                "enclosed volume   %.6g\n",
                level_set.name().c_str(), level_set.voxel_size(), level_set.background(), lo.x(),
                lo.y(), lo.z(), hi.x(), hi.y(), hi.z(),
                static_cast<long long>(level_set.num_active_voxels()), level_set_volume(level_set));
  return buffer;
}

}  // namespace strata
