#pragma once
/// \file polar_decomposition.hpp
/// Fast 3 × 3 rotation-variant SVD and polar rotation with inversion handling (Irving, Teran,
/// Fedkiw 2004, "Invertible finite elements for robust simulation of large deformation").
///
/// Method: one-sided (Hestenes) Jacobi. The columns of B = F V are orthogonalised pairwise by plane
/// rotations accumulated into V, until |b_p · b_q| ≤ 1e-15 ‖b_p‖ ‖b_q‖ for every pair (quadratic
/// convergence; 2–3 sweeps for a moderate strain, at most 12). Implicitly this diagonalises FᵀF
/// without forming it, so small singular values keep their relative accuracy. The columns are then
/// sorted by length; U = [u₀, u₁, u₀ × u₁] with u₀ = b₀/‖b₀‖, u₁ the normalised part of b₁
/// orthogonal to u₀ (any unit vector ⟂ u₀ if that part vanishes), and σ₂ takes the sign of u₂ · b₂.
/// V is made proper by flipping v₂ (and b₂) when the column sorting left det V = −1. Inputs whose
/// largest entry lies outside [1e-100, 1e100] are scaled by a power of two first.
///
/// Accuracy (measured in tests/core/test_fem_polar_decomposition.cpp against Eigen::JacobiSVD):
/// U, V orthonormal to ~1e-15, F = U diag(σ) Vᵀ to ~1e-15 ‖F‖, σ to ~1e-15 σ₀, and R = U Vᵀ to
/// ~1e-15 σ₀ / min_{i<j}(σᵢ + σⱼ), the conditioning of the polar rotation itself (R is not unique
/// when some σᵢ + σⱼ = 0, e.g. rank ≤ 1 or a reflection with |σ₁| = |σ₂|; any valid R is returned).
#include "strata/core/common/types.hpp"

namespace strata {

/// F = U diag(σ) Vᵀ with U, V proper rotations (det = +1) and σ₀ ≥ σ₁ ≥ |σ₂|, σ₀, σ₁ ≥ 0.
/// σ₂ < 0 exactly when the element is inverted (det F < 0; for |det F| at round-off level the sign
/// follows the computed orientation). All 3 × 3.
struct RotationVariantSvd {
  Matrix3d U;
  Vector3d sigma;
  Matrix3d V;
};

/// Rotation-variant SVD of a 3 × 3 matrix (any F, including singular, zero and inverted ones).
RotationVariantSvd rotation_variant_svd(const Matrix3d& F);

/// Rotation R = U Vᵀ (det R = +1) of the polar decomposition F = R S, S = V diag(σ) Vᵀ symmetric
/// with at most its smallest eigenvalue negative (negative iff det F < 0).
Matrix3d polar_rotation(const Matrix3d& F);

}  // namespace strata
