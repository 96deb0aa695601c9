#pragma once
/// \file psd_projection.hpp
/// Projection of a symmetric matrix onto the positive semi-definite cone (negative eigenvalues
/// clamped to zero), used to keep Newton's linear systems solvable in implicit solves.
#include "strata/core/common/types.hpp"

namespace strata {

/// Nearest PSD matrix (Frobenius norm) to the symmetric part of `A`.
template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A);

extern template Matrix9d project_to_psd<9>(const Matrix9d&);
extern template Matrix12d project_to_psd<12>(const Matrix12d&);

}  // namespace strata
