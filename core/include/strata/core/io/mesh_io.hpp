#pragma once
/// \file mesh_io.hpp
/// Tet mesh files by extension: .msh (gmsh 2.2 / 4.1 ASCII), .mesh (Medit ASCII),
/// .node / .ele (TetGen), .vtu (VTK XML unstructured grid). Extensions are case-insensitive.
#include <filesystem>
#include <string>

#include "strata/core/io/gmsh.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

enum class MeshFormat { gmsh, medit, tetgen, vtu };

/// The format a path's extension names; throws InputError naming the path for any other.
MeshFormat mesh_format_of(const std::filesystem::path& path);

/// Options of `write_tet_mesh` that only some formats use.
struct MeshWriteOptions {
  GmshVersion gmsh_version = GmshVersion::v4_1;  ///< .msh flavour
};

/// Reads a tet mesh in the format named by the extension. The mesh is returned raw (as stored):
/// callers run validate_tet_mesh / orient_tets. Throws InputError naming the file on a missing
/// file, an unknown extension or malformed content.
TetMesh read_tet_mesh(const std::filesystem::path& path);

/// Writes `mesh` in the format named by the extension, atomically (TetGen: both files).
void write_tet_mesh(const std::filesystem::path& path, const TetMesh& mesh,
                    const MeshWriteOptions& options = {});

/// Reads `in` and writes it to `out` unchanged (formats from the extensions).
void convert_tet_mesh(const std::filesystem::path& in, const std::filesystem::path& out,
                      const MeshWriteOptions& options = {});

}  // namespace strata
