#pragma once
/// \file mesh_cache.hpp
/// A folder of generated tet meshes keyed by a hash of their input, so re-running a scene does not
/// re-mesh. Entries are .vtu files (numbers written round-trip exact), written atomically.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/meshing_options.hpp"

namespace strata {

/// 64-bit FNV-1a of `bytes`, continuing from `hash`.
std::uint64_t fnv1a_64(const std::string& bytes, std::uint64_t hash = 0xcbf29ce484222325ull);

/// Cache key of meshing `input` with `options` and `route` (e.g. "polyhedral" or a level-set
/// description): 16 hex digits of the hash of the file's bytes, every option (round-trip exact),
/// `route` and a format version. InputError naming the file when it cannot be read.
std::string meshing_cache_key(const std::filesystem::path& input, const MeshingOptions& options,
                              const std::string& route);

/// Cache key of an input given as bytes (e.g. a canonical description of an implicit shape):
/// meshing_cache_key(file, ...) equals meshing_cache_key_of_bytes(<the file's bytes>, ...).
std::string meshing_cache_key_of_bytes(const std::string& bytes, const MeshingOptions& options,
                                       const std::string& route);

/// Generated meshes in one folder, one file `<key>.vtu` per entry.
class MeshCache {
 public:
  explicit MeshCache(std::filesystem::path folder) : m_folder(std::move(folder)) {}

  const std::filesystem::path& folder() const { return m_folder; }
  std::filesystem::path entry_path(const std::string& key) const;

  /// The cached mesh, or nothing when there is no readable, valid entry (a corrupt entry is
  /// treated as a miss and overwritten by the next store).
  std::optional<TetMesh> load(const std::string& key) const;
  /// Writes the entry atomically (creating the folder); InputError naming the file on failure.
  void store(const std::string& key, const TetMesh& mesh) const;

 private:
  std::filesystem::path m_folder;
};

}  // namespace strata
