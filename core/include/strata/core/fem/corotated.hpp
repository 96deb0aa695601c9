#pragma once
/// \file corotated.hpp
/// Corotated linear elasticity: ψ(F) = μ ‖F − R‖²_F + λ/2 tr(RᵀF − I)², with F = R S the polar
/// decomposition (R a proper rotation, computed from the rotation-variant SVD with inversion
/// handling as in Irving, Teran, Fedkiw 2004; see polar_decomposition.hpp).
/// P = 2μ(F − R) + λ tr(RᵀF − I) R.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/fem/polar_decomposition.hpp"

namespace strata {

double psi_corotated(const Matrix3d& F, const LameParameters& lame);
Matrix3d dpsi_corotated_dF(const Matrix3d& F, const LameParameters& lame);
/// ∂²ψ/∂F² on column-major vec(F) (9 × 9), including the derivative of R.
Matrix9d d2psi_corotated_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
