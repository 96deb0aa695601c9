#pragma once
/// \file red_refinement.hpp
/// Red (1:8) refinement of one tetrahedron with Bey's ordering rule (J. Bey, "Tetrahedral grid
/// refinement", Computing 55, 1995, Algorithm RedRefinement).
///
/// A parent T = [x0, x1, x2, x3] (ordered) and its edge midpoints x_ij = ½(x_i + x_j) form ten
/// "refinement points", numbered 0..3 for x0..x3 and 4..9 for x01, x02, x03, x12, x13, x23
/// (`kTetEdges`). The children, each an *ordered* tet, are
///
///     T0 = [x0,  x01, x02, x03]   T4 = [x01, x02, x03, x13]
///     T1 = [x01, x1,  x12, x13]   T5 = [x01, x02, x12, x13]
///     T2 = [x02, x12, x2,  x23]   T6 = [x02, x03, x13, x23]
///     T3 = [x03, x13, x23, x3 ]   T7 = [x02, x12, x13, x23]
///
/// i.e. four corner tets and the inner octahedron cut along its x02–x13 diagonal. Refining the
/// children again with the same rule *in these vertex orders* produces tets of at most three
/// similarity classes at every depth (Bey, Theorem 1), so the shape quality never decays.
///
/// Orientation: the affine map from the parent's ordered vertices to a child's is fixed per child
/// slot, so sign(vol child) = sign(vol parent) · kBeyChildOrientation[k]. T5 and T7 come out
/// mirrored (negative when the parent is positive). Bey's order must be kept for the next
/// refinement, so the tree stores it unchanged plus an orientation sign and only swaps two vertices
/// when it hands out a tet for simulation (`oriented_tet`).
#include <array>

#include "strata/core/common/types.hpp"

namespace strata {

/// Local vertex pairs of the six tet edges; edge e has refinement point 4 + e as its midpoint.
inline constexpr std::array<std::array<int, 2>, 6> kTetEdges = {
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

/// Children in Bey's vertex order, as refinement points 0..9 (see the file comment).
inline constexpr std::array<std::array<int, 4>, 8> kBeyChildren = {{{0, 4, 5, 6},
                                                                    {4, 1, 7, 8},
                                                                    {5, 7, 2, 9},
                                                                    {6, 8, 9, 3},
                                                                    {4, 5, 6, 8},
                                                                    {4, 5, 7, 8},
                                                                    {5, 6, 8, 9},
                                                                    {5, 7, 8, 9}}};

/// sign(vol child k) / sign(vol parent) for Bey-ordered parent and children (+1 or −1).
inline constexpr std::array<int, 8> kBeyChildOrientation = {1, 1, 1, 1, 1, -1, 1, -1};

/// The ten refinement points of the tet with columns x0..x3: columns 0..3 are the vertices,
/// columns 4..9 the midpoints of `kTetEdges`. 3 × 10.
Eigen::Matrix<double, 3, 10> refinement_points(const Matrix3x4d& x);

/// The eight children (columns = Bey-ordered vertices) of the Bey-ordered tet x.
std::array<Matrix3x4d, 8> red_refine_tet(const Matrix3x4d& x);

/// The 4 × 4 matrix M_k mapping barycentric coordinates λ of a point in the parent (w.r.t. its
/// Bey-ordered vertices) to its coordinates μ = M_k λ in child k (w.r.t. the child's Bey-ordered
/// vertices). Entries are small integers, so the map is exact in floating point up to the final
/// sums. The point lies in child k iff all μ ≥ 0.
const Eigen::Matrix4d& bey_child_barycentric_map(int child);

/// Tet vertex order handed out for simulation: Bey order if `orientation` > 0, else Bey order with
/// the last two vertices swapped (x0, x1, x3, x2), which flips the sign of the volume.
inline std::array<int, 4> oriented_tet(const std::array<int, 4>& bey_order, int orientation) {
  if (orientation > 0) return bey_order;
  return {bey_order[0], bey_order[1], bey_order[3], bey_order[2]};
}

}  // namespace strata
