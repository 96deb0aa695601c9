#pragma once
/// \file isotropic_hessian.hpp
/// The Hessian ∂²ψ/∂F² of an isotropic energy ψ(F) = Ψ̂(σ(F)) in its singular-value frame, and its
/// PSD projection in closed form (Teran, Sifakis, Irving, Fedkiw 2005, "Robust quasistatic finite
/// elements and flesh simulation"; Smith, de Goes, Kim 2019, "Analytic eigensystems for isotropic
/// distortion energies").
///
/// With F = U diag(σ) Vᵀ (rotation-variant SVD, σ₂ < 0 for inverted F), dF̂ = Uᵀ dF V and
/// dP̂ = Uᵀ dP V, the 9 × 9 Hessian decouples into
/// - a 3 × 3 block on the diagonal entries: dP̂_ii = Σ_j (∂²Ψ̂/∂σ_i∂σ_j) dF̂_jj, and
/// - per pair (i, j) ∈ {(0,1), (0,2), (1,2)} a 2 × 2 block on (dF̂_ij, dF̂_ji) with the
///   eigenvectors (1, 1)/√2 ("flip", eigenvalue (ψ_i − ψ_j)/(σ_i − σ_j)) and (1, −1)/√2 ("twist",
///   eigenvalue (ψ_i + ψ_j)/(σ_i + σ_j)), ψ_i = ∂Ψ̂/∂σ_i.
/// Both pair eigenvalues are written division-free for StVK and stable neo-Hookean (exact for equal
/// singular values); the corotated twist divides by σ_i + σ_j exactly as d2psi_corotated_dF2 does.
/// Clamping the 9 eigenvalues (three of the 3 × 3 block, six pair modes) to ≥ 0 and rebuilding
/// gives the nearest PSD matrix, the same as project_to_psd<9>(d2psi_dF2(F)) at a fraction of its
/// cost.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/fem/polar_decomposition.hpp"

namespace strata {

/// ∂²ψ/∂F² of one model at one F, in the singular-value frame.
struct SingularFrameHessian {
  RotationVariantSvd svd;
  Matrix3d sigma_hessian;  ///< ∂²Ψ̂/∂σ² (3 × 3, symmetric)
  Vector3d flip;           ///< (ψ_i − ψ_j)/(σ_i − σ_j) for the pairs (0,1), (0,2), (1,2)
  Vector3d twist;          ///< (ψ_i + ψ_j)/(σ_i + σ_j) for the same pairs
};

/// Per model: ∂²Ψ̂/∂σ², flip and twist at the singular values `sigma` (h.svd is left alone).
void stvk_singular_frame(const Vector3d& sigma, const LameParameters& lame,
                         SingularFrameHessian& h);
void corotated_singular_frame(const Vector3d& sigma, const LameParameters& lame,
                              SingularFrameHessian& h);
void neohookean_singular_frame(const Vector3d& sigma, const LameParameters& lame,
                               SingularFrameHessian& h);

/// The frame form of ∂²ψ/∂F² for `model` at F (any F, including inverted and singular ones).
SingularFrameHessian singular_frame_hessian(MaterialModel model, const Matrix3d& F,
                                            const LameParameters& lame);

/// The 9 × 9 matrix (column-major vec(F)) of a frame-form Hessian; with `project_psd`, negative
/// eigenvalues are clamped to zero first (the nearest PSD matrix in the Frobenius norm).
Matrix9d frame_hessian_matrix(const SingularFrameHessian& hessian, bool project_psd);

/// PSD projection of ∂²ψ/∂F² (9 × 9) in closed form; equals project_to_psd<9>(d2psi_dF2(...)).
Matrix9d d2psi_dF2_psd(MaterialModel model, const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
