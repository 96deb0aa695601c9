#pragma once
/// \file polar_decomposition.hpp
/// Fast 3 × 3 rotation-variant SVD and polar rotation with inversion handling (Irving, Teran,
/// Fedkiw 2004, "Invertible finite elements for robust simulation of large deformation").
///
/// rotation_variant_svd — one-sided (Hestenes) Jacobi: the columns of B = F V are orthogonalised
/// pairwise by plane rotations accumulated into V until |b_p · b_q| ≤ 1e-15 ‖b_p‖ ‖b_q‖ for every
/// pair, or a whole sweep only rotated by angles below 1e-8 (≈ 4 sweeps, 9 rotations for a
/// moderate strain; at most 12 sweeps). This diagonalises FᵀF without forming it. The columns are
/// then sorted by length; U = [u₀, u₁, u₀ × u₁] with u₀ = b₀/‖b₀‖, u₁ the normalised part of b₁
/// orthogonal to u₀ (any unit vector ⟂ u₀ if that part vanishes), and σ₂ = ±‖b₂‖ with the sign of
/// u₂ · b₂. V is made proper by flipping v₂ (and b₂) when the sorting left det V = −1. Inputs
/// whose largest entry lies outside [1e-100, 1e100] are scaled by a power of two first.
///
/// polar_rotation — for det F > 0 (and F not nearly flat) the scaled Newton iteration
/// X ← (γX + X⁻ᵀ/γ)/2 of Higham 1986 ("Computing the polar decomposition — with applications"),
/// with Frobenius scaling γ while X is far from orthogonal and a stop once ‖ΔX‖_F ≤ 1e-7
/// (quadratic convergence: error ≈ ‖ΔX‖²/2); 3–4 iterations for a moderate strain. Inverted,
/// nearly flat, extremely scaled or non-converging F fall back to rotation_variant_svd.
///
/// Accuracy (tests/core/test_fem_polar_decomposition.cpp, 10k matrices of 16 kinds at scales 1,
/// 1e-8, 1e8, against Eigen::JacobiSVD): U, V orthonormal to 2e-15, F = U diag(σ) Vᵀ to 2e-15 ‖F‖,
/// σ to 2e-15 σ₀, RᵀF symmetric to 2e-15 σ₀, and R (both paths) to 7e-15 σ₀ / min_{i<j}(σᵢ + σⱼ),
/// the conditioning of the polar rotation itself. R is not unique when some σᵢ + σⱼ = 0 (rank ≤ 1,
/// or a reflection with |σ₁| = |σ₂|); a valid one (proper, RᵀF symmetric) is returned.
/// Cost (x86-64-v3, F near a rotation): polar_rotation ≈ 80 ns, rotation_variant_svd ≈ 340 ns,
/// Eigen::JacobiSVD with full U, V ≈ 630 ns.
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
