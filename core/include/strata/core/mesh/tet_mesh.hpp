#pragma once
/// \file tet_mesh.hpp
/// A linear tetrahedral mesh: rest positions and tets, with validation and orientation.
#include <array>
#include <string>

#include "strata/core/common/compressed_lists.hpp"
#include "strata/core/common/types.hpp"

namespace strata {

/// A tetrahedral mesh in its rest configuration.
struct TetMesh {
  MatrixX3d vertices;  ///< #V × 3 rest positions [m]
  MatrixX4i tets;      ///< #T × 4 vertex indices; positively oriented after `orient_tets`
};

/// Signed volume of the tet (x0, x1, x2, x3): det([x1−x0, x2−x0, x3−x0]) / 6.
double tet_signed_volume(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                         const Vector3d& x3);

/// Volume relative to the cube of the longest edge, normalised so a regular tet gives 1:
/// 6√2 · V / ℓ_max³. Degenerate (flat or collapsed) tets give ≈ 0.
double tet_normalized_volume(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                             const Vector3d& x3);

/// Tets whose |normalized volume| is below this are degenerate (an input error).
inline constexpr double kDegenerateTetThreshold = 1e-8;

/// Checks a mesh read from `source` (a file name or "box"): at least one tet, finite coordinates,
/// indices in range, four distinct vertices per tet, no degenerate tet. Throws InputError naming
/// `source` and the element index.
void validate_tet_mesh(const TetMesh& mesh, const std::string& source);

/// Swaps two vertices of every negatively oriented tet so all have positive volume; returns how
/// many were flipped. Call after `validate_tet_mesh`.
Index orient_tets(TetMesh& mesh);

/// Removes vertices that no tet references and renumbers the tets; returns how many were removed.
Index remove_unreferenced_vertices(TetMesh& mesh);

/// Boundary triangles: tet faces used by exactly one tet, ordered so that their normal
/// (x1−x0)×(x2−x0) points out of the mesh. #F × 3. Requires positively oriented tets.
MatrixX3i boundary_faces(const MatrixX4i& tets);

/// For each of `num_vertices` vertices, the tets that use it, ascending.
CompressedLists vertex_tets(const MatrixX4i& tets, Index num_vertices);

/// For each of `num_vertices` vertices, the vertices that share a tet with it (itself included if
/// it is in a tet), ascending: the block pattern of a stiffness matrix.
CompressedLists vertex_neighbours(const MatrixX4i& tets, Index num_vertices);

/// Axis-aligned bounding box of a point set: (min, max).
std::pair<Vector3d, Vector3d> bounding_box(ConstRef<MatrixX3d> points);

/// Total rest volume (sum of signed tet volumes).
double mesh_volume(const TetMesh& mesh);

/// A box [min, max] split into cells[0] × cells[1] × cells[2] hexahedral cells, each split into
/// six tets around its main diagonal (Kuhn/Freudenthal split), each cell mirrored along the axes
/// where its index is odd so that the diagonals alternate: conforming, positively oriented and
/// without a preferred direction.
/// Throws InputError if a cell count is < 1 or the box is empty.
TetMesh box_tet_mesh(const Vector3d& min, const Vector3d& max, const std::array<int, 3>& cells);

}  // namespace strata
