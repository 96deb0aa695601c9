#pragma once
/// \file triangle_frame_binding.hpp
/// A fine surface carried by a coarse triangle surface (a simplified copy of it, for example).
///
/// Each fine vertex X is bound to the coarse triangle (x0, x1, x2) nearest to it at rest, in that
/// triangle's frame: X = x0 + a (x1 − x0) + b (x2 − x0) + c n̂, with n̂ the unit normal of
/// (x1 − x0) × (x2 − x0). The deformed vertex applies the same coefficients to the deformed
/// triangle, so a rigid motion of the coarse surface moves the fine one rigidly (to rounding), a
/// fine vertex on its triangle moves with the triangle's linear interpolation, and c, the signed
/// distance along the normal, keeps its length.
#include "strata/core/common/types.hpp"

namespace strata {

struct TriangleFrameBinding {
  VectorXi triangles;      ///< #Vf bound coarse triangle
  MatrixX3d coefficients;  ///< #Vf × 3 (a, b, c); c [m]
  VectorXd distance;       ///< #Vf distance from the rest vertex to its triangle [m]
};

/// Binds each row of `fine_vertices` (#Vf × 3) to the nearest non-degenerate triangle of the coarse
/// surface (`coarse_vertices` #V × 3, `coarse_triangles` #F × 3, the nearest point from a BVH).
/// Parallel over the fine vertices. Throws InputError for a triangle index out of range, a coarse
/// surface without a non-degenerate triangle, or a non-finite fine vertex (naming it).
TriangleFrameBinding bind_to_triangles(ConstRef<MatrixX3d> coarse_vertices,
                                       ConstRef<MatrixX3i> coarse_triangles,
                                       ConstRef<MatrixX3d> fine_vertices);

/// The fine vertices (#Vf × 3) for the coarse vertices at `positions` (3·#P, vertex-major, #P ≥ the
/// largest vertex index of `coarse_triangles` + 1: further points, a skeleton say, may follow).
MatrixX3d deformed_points(const TriangleFrameBinding& binding, ConstRef<MatrixX3i> coarse_triangles,
                          ConstRef<VectorXd> positions);

}  // namespace strata
