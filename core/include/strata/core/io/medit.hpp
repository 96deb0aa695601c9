#pragma once
/// \file medit.hpp
/// Medit / INRIA .mesh files, ASCII (https://www.ljll.fr/frey/publications/RT-0253.pdf).
#include <filesystem>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// Reads `Vertices` (x y z ref) and `Tetrahedra` (4 1-based vertex indices + ref) of an ASCII
/// .mesh file. Keywords are case-insensitive; other sections (Triangles, Edges, Corners, ...) are
/// skipped; `#` starts a comment; reading stops at `End`. Only `Dimension 3` is accepted.
/// Throws InputError naming the file and line on malformed input or a mesh without tets.
TetMesh read_medit(const std::filesystem::path& path);

/// Writes vertices (reference 0) and tets (reference 1) as an ASCII .mesh file, atomically.
void write_medit(const std::filesystem::path& path, const TetMesh& mesh);

}  // namespace strata
