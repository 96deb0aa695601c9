#pragma once
/// \file tetgen.hpp
/// TetGen .node / .ele file pairs (https://wias-berlin.de/software/tetgen/fformats.html).
#include <filesystem>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// Reads a TetGen mesh given either `name.node` or `name.ele` (the sibling is found by replacing
/// the extension). The first point index in .node (0 or 1) sets the numbering of both files;
/// attributes and boundary markers are skipped; for 10-node tets the 4 corners are kept; `#`
/// starts a comment. Throws InputError naming the file and line on malformed input.
TetMesh read_tetgen(const std::filesystem::path& path);

/// Writes `name.node` and `name.ele` (1-based, no attributes or markers), each atomically; `path`
/// may carry either extension.
void write_tetgen(const std::filesystem::path& path, const TetMesh& mesh);

}  // namespace strata
