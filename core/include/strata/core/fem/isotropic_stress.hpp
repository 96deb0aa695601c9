#pragma once
/// \file isotropic_stress.hpp
/// The lecture's isotropic stress–strain law in Voigt form, {σ} = C {ε} with
/// {ε} = [εxx, εyy, εzz, εxy, εyz, εxz] (tensor shear components) and
/// C = E/((1+ν)(1−2ν)) [[1−ν, ν, ν, 0, 0, 0], …, [0, …, 1−2ν]], which equals the tensor form
/// σ = λ tr(ε) I + 2μ ε.
#include "strata/core/common/types.hpp"

namespace strata {

/// Symmetric 3 × 3 tensor → Voigt vector [xx, yy, zz, xy, yz, xz].
Vector6d to_voigt(const Matrix3d& symmetric);

/// Voigt vector [xx, yy, zz, xy, yz, xz] → symmetric 3 × 3 tensor.
Matrix3d from_voigt(const Vector6d& voigt);

/// The lecture's 6 × 6 isotropic elasticity matrix for Young's modulus E and Poisson ratio ν.
Matrix6d isotropic_voigt_matrix(double youngs_modulus, double poisson_ratio);

/// Isotropic stress of a strain tensor through the Voigt matrix: from_voigt(C · to_voigt(ε)).
Matrix3d isotropic_voigt_stress(const Matrix3d& strain, double youngs_modulus,
                                double poisson_ratio);

/// von Mises equivalent stress √(3/2 s:s), s the deviator of the (Cauchy) stress σ.
double von_mises_stress(const Matrix3d& sigma);

/// Cauchy stress σ = P Fᵀ / J from the first Piola stress P.
inline Matrix3d cauchy_stress(const Matrix3d& P, const Matrix3d& F) {
  return P * F.transpose() / F.determinant();
}

}  // namespace strata
