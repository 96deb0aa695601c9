#include "strata/meshing/mesh_cache.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"

namespace strata {
namespace {

/// Bump when the meshing pipeline changes its output for the same input and options.
constexpr const char* kCacheFormat = "strata-mesh-cache-1";

}  // namespace

std::uint64_t fnv1a_64(const std::string& bytes, std::uint64_t hash) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::string meshing_cache_key(const std::filesystem::path& input, const MeshingOptions& options,
                              const std::string& route) {
  std::ifstream in(input, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  if (!in) throw InputError(input.string() + ": cannot read");
  return meshing_cache_key_of_bytes(content.str(), options, route);
}

std::string meshing_cache_key_of_bytes(const std::string& bytes, const MeshingOptions& options,
                                       const std::string& route) {
  std::ostringstream parameters;
  parameters.precision(17);
  parameters << kCacheFormat << '|' << route << '|' << options.cell_size << '|'
             << options.facet_size << '|' << options.facet_distance << '|' << options.facet_angle
             << '|' << options.cell_radius_edge_ratio << '|' << options.sharp_features << '|'
             << options.feature_angle << '|' << options.odt << '|' << options.lloyd << '|'
             << options.perturb << '|' << options.exude << '|' << options.sliver_bound << '|'
             << options.seed;
  const std::uint64_t hash = fnv1a_64(parameters.str(), fnv1a_64(bytes));
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

std::filesystem::path MeshCache::entry_path(const std::string& key) const {
  return m_folder / (key + ".vtu");
}

std::optional<TetMesh> MeshCache::load(const std::string& key) const {
  const std::filesystem::path path = entry_path(key);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
  try {
    TetMesh mesh = read_tet_mesh(path);
    validate_tet_mesh(mesh, path.string());
    return mesh;
  } catch (const InputError&) {
    return std::nullopt;
  }
}

void MeshCache::store(const std::string& key, const TetMesh& mesh) const {
  std::error_code error;
  std::filesystem::create_directories(m_folder, error);
  if (error) throw InputError(m_folder.string() + ": cannot create the mesh cache folder");
  write_tet_mesh(entry_path(key), mesh);
}

}  // namespace strata
