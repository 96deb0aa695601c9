#pragma once
// Internal: the CGAL-free steps shared by the Mesh_3 translation units.
#include <string>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/meshing_options.hpp"

namespace strata::detail {

/// options with the defaults of facet_size (cell_size) and facet_distance (cell_size / 10) filled.
MeshingOptions resolved_meshing_options(const MeshingOptions& options);

/// Validates Mesh_3's output: throws InputError("<what>: ...") when it has no tet; removes unused
/// vertices, orients the tets positively and validates the mesh.
TetMesh finish_tet_mesh(TetMesh mesh, const std::string& what);

}  // namespace strata::detail
