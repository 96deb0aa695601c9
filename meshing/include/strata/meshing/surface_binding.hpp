#pragma once
/// \file surface_binding.hpp
/// A fine render surface carried by a coarse simulation tet mesh.
///
/// Each fine vertex X is bound to a tet of the rest mesh by barycentric coordinates λ
/// (Σλ = 1, Σ λ_k X_k = X); the deformed vertex is x = Σ λ_k x_k, the tet's affine map applied to
/// X. Vertices inside the mesh use their containing tet (λ ≥ 0); vertices outside (or in a gap of a
/// non-convex mesh) use the nearest tet, with extrapolated coordinates (some λ < 0), so they
/// follow the nearest tet's affine motion. Rigid motions of the tet mesh therefore move the fine
/// surface rigidly, to rounding.
///
/// The displacement map is the other view of the same detail: each fine vertex as a point of the
/// coarse mesh's own boundary surface plus an offset along that surface's normal, so a renderer can
/// draw the coarse surface and displace it ("details into bump maps").
#include "strata/core/common/types.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// Per fine vertex: its tet and barycentric coordinates.
struct SurfaceBinding {
  MatrixX4i corners;  ///< #Vs × 4 vertex indices of the bound tet
  Eigen::Matrix<double, Eigen::Dynamic, 4> barycentric;  ///< #Vs × 4, rows sum to 1
  VectorXi tets;                                         ///< #Vs bound tet index
  VectorXd distance;      ///< #Vs distance from the rest vertex to its tet [m]; 0 inside
  Index num_outside = 0;  ///< vertices bound to a nearest (not containing) tet
};

/// Binds each row of `surface_vertices` (#Vs × 3, rest positions) to `rest_mesh` (#V × 3, #T × 4,
/// non-degenerate). Containing tets come from a TetLocator grid, nearest tets from a BVH over
/// the mesh's boundary triangles (the nearest point of the solid to an outside point lies on its
/// boundary). Parallel over vertices. Throws InputError naming the vertex for non-finite
/// coordinates, or for an empty mesh.
SurfaceBinding bind_surface(const TetMesh& rest_mesh, ConstRef<MatrixX3d> surface_vertices);

/// Deformed fine vertices (#Vs × 3) for tet-mesh positions (3·#V, vertex-major).
MatrixX3d deformed_surface(const SurfaceBinding& binding, ConstRef<VectorXd> positions);

/// Boundary triangles of a tet mesh with the tet owning each (faces used by exactly one tet),
/// oriented outward (for either tet orientation).
struct TetBoundary {
  MatrixX3i faces;  ///< #Fb × 3 vertex indices, normal (x1−x0)×(x2−x0) pointing out
  VectorXi tets;    ///< #Fb owning tet
};
TetBoundary tet_boundary(const TetMesh& mesh);

/// Per fine vertex: base point on the coarse boundary surface and offset along its normal.
struct DisplacementMap {
  MatrixX3i boundary_faces;  ///< #Fb × 3 the coarse boundary (indices into the tet mesh vertices)
  VectorXi faces;            ///< #Vs index of the closest boundary face
  MatrixX3d face_barycentric;  ///< #Vs × 3 coordinates of the closest point in that face
  /// #Vs signed offset [m]: |X − c| for the closest boundary point c, positive when X lies on the
  /// outer side of the closest face ((X − c)·n > 0), negative inside.
  VectorXd offset;
};

/// Closest points on `rest_mesh`'s boundary triangles (BVH) and signed offsets of
/// `surface_vertices` (#Vs × 3).
DisplacementMap displacement_map(const TetMesh& rest_mesh, ConstRef<MatrixX3d> surface_vertices);

/// Coarse surface + map: base point (barycentric in the deformed face) + offset × the deformed
/// face's unit normal, #Vs × 3, for positions 3·#V. At rest it gives back X wherever X's closest
/// boundary point lies inside a face (not on an edge or corner).
MatrixX3d displaced_surface(const DisplacementMap& map, ConstRef<VectorXd> positions);

}  // namespace strata
