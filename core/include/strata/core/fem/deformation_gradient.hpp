#pragma once
/// \file deformation_gradient.hpp
/// Deformation gradient of a linear tet: F = Ds · Dm⁻¹ with Ds = [x1−x0, x2−x0, x3−x0] (deformed)
/// and Dm the same edge matrix at rest (the lecture's P = [p1 p2 p3][x1 x2 x3]⁻¹).
#include "strata/core/common/types.hpp"

namespace strata {

/// Edge matrix [x1−x0, x2−x0, x3−x0] of the tet whose vertices are the columns of `x`.
inline Matrix3d edge_matrix(const Matrix3x4d& x) {
  Matrix3d D;
  D.col(0) = x.col(1) - x.col(0);
  D.col(1) = x.col(2) - x.col(0);
  D.col(2) = x.col(3) - x.col(0);
  return D;
}

/// F = Ds(x) · Dm_inv for deformed vertex positions `x` (columns x0..x3).
inline Matrix3d deformation_gradient(const Matrix3x4d& x, const Matrix3d& Dm_inv) {
  return edge_matrix(x) * Dm_inv;
}

/// ∂vec(F)/∂x (9 × 12), vec column-major (vec(F)[3c + r] = F(r, c)), x = (x0, x1, x2, x3).
Eigen::Matrix<double, 9, 12> deformation_gradient_jacobian(const Matrix3d& Dm_inv);

/// Shape-function gradients at rest: row k of the returned 4 × 3 matrix is ∇N_k (constant in the
/// tet), so F = Σ_k x_k ∇N_kᵀ.
Eigen::Matrix<double, 4, 3> shape_function_gradients(const Matrix3d& Dm_inv);

}  // namespace strata
