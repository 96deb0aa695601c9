#pragma once
/// \file triangle_frame_binding.hpp
/// A fine surface carried by a coarse triangle surface (a simplified copy of it, for example).
///
/// Each fine vertex X is bound to the coarse triangle (x0, x1, x2) nearest to it at rest: the
/// nearest point p = Σ βᵢ xᵢ (barycentric, βᵢ ≥ 0) and the offset X − p in the triangle's
/// orthonormal frame R = (t, n̂ × t, n̂), t along the triangle's longest edge and n̂ its unit normal.
/// The deformed vertex is Σ βᵢ xᵢ' + R' o with the deformed triangle's frame R', so a rigid motion
/// of the coarse surface moves the fine one rigidly (to rounding), a fine vertex on its triangle
/// follows the triangle's linear interpolation (affine maps exactly), and the offset keeps its
/// length. The frame is well conditioned for any triangle of positive area; a triangle that
/// collapses while deforming has no normal, and its vertices keep only their offset's tangential
/// part.
#include "strata/core/common/types.hpp"

namespace strata {

struct TriangleFrameBinding {
  VectorXi triangles;  ///< #Vf bound coarse triangle
  VectorXi edges;  ///< #Vf edge k (x_k → x_{k+1}) of that triangle t follows: the longest at rest
  MatrixX3d barycentric;  ///< #Vf × 3 nearest point's coordinates in that triangle
  MatrixX3d offset;       ///< #Vf × 3 X − p in the triangle's frame (t, n̂ × t, n̂) [m]
  VectorXd distance;      ///< #Vf distance from the rest vertex to its triangle [m]
};

/// Binds each row of `fine_vertices` (#Vf × 3) to the nearest triangle of positive area of the
/// coarse surface (`coarse_vertices` #V × 3, `coarse_triangles` #F × 3; nearest points from a BVH).
/// Parallel over the fine vertices. Throws InputError for a triangle index out of range, a coarse
/// surface without a triangle of positive area, or a non-finite fine vertex (naming it).
TriangleFrameBinding bind_to_triangles(ConstRef<MatrixX3d> coarse_vertices,
                                       ConstRef<MatrixX3i> coarse_triangles,
                                       ConstRef<MatrixX3d> fine_vertices);

/// The fine vertices (#Vf × 3) for the coarse vertices at `positions` (3·#P, vertex-major, #P ≥ the
/// largest vertex index of `coarse_triangles` + 1: further points, a skeleton say, may follow).
MatrixX3d deformed_points(const TriangleFrameBinding& binding, ConstRef<MatrixX3i> coarse_triangles,
                          ConstRef<VectorXd> positions);

/// The fine vertices' velocities (#Vf × 3): the derivative of deformed_points along the coarse
/// velocities `velocities` (3·#P) at `positions`, the turning frame included.
MatrixX3d deformed_velocities(const TriangleFrameBinding& binding,
                              ConstRef<MatrixX3i> coarse_triangles, ConstRef<VectorXd> positions,
                              ConstRef<VectorXd> velocities);

}  // namespace strata
