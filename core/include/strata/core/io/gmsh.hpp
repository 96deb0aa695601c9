#pragma once
/// \file gmsh.hpp
/// Gmsh .msh files, ASCII format 2.2 and 4.1
/// (http://gmsh.info/doc/texinfo/gmsh.html#MSH-file-format).
#include <filesystem>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// Format versions the writer can produce.
enum class GmshVersion { v2_2, v4_1 };

/// Reads the linear tetrahedra (element type 4) of an ASCII .msh file, version 2.2 or 4.1.
/// Other element types (points, lines, triangles, ...) are skipped; node tags may be
/// non-contiguous and are mapped to 0-based vertex indices in the order of the $Nodes section.
/// Throws InputError naming the file and line on malformed input, on binary files and on a mesh
/// without tets. The mesh is returned raw: run validate_tet_mesh / orient_tets afterwards.
TetMesh read_gmsh(const std::filesystem::path& path);

/// Writes vertices (node tags 1..#V) and tets (element type 4, tags 1..#T) as an ASCII .msh file,
/// atomically. Version 4.1 puts everything into one volume entity.
void write_gmsh(const std::filesystem::path& path, const TetMesh& mesh,
                GmshVersion version = GmshVersion::v4_1);

}  // namespace strata
