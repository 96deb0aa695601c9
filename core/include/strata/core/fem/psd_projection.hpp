#pragma once
/// \file psd_projection.hpp
/// Projection of a symmetric matrix onto the positive semi-definite cone (negative eigenvalues
/// clamped to zero), used to keep Newton's linear systems solvable in implicit solves.
/// Generic (any symmetric matrix, by eigen-decomposition). The element stiffness projects ∂²ψ/∂F²
/// in closed form instead (d2psi_dF2_psd in isotropic_hessian.hpp, tested against this).
#include "strata/core/common/types.hpp"

namespace strata {

/// Nearest PSD matrix (Frobenius norm) to the symmetric part of `A`.
template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A);

extern template Matrix9d project_to_psd<9>(const Matrix9d&);
extern template Matrix12d project_to_psd<12>(const Matrix12d&);

}  // namespace strata
