#pragma once
/// \file corotated.hpp
/// Corotated linear elasticity: ψ(F) = μ ‖F − R‖²_F + λ/2 tr(RᵀF − I)², with F = R S the polar
/// decomposition (R a proper rotation, computed from the SVD with inversion handling as in
/// Irving, Teran, Fedkiw 2004). P = 2μ(F − R) + λ tr(RᵀF − I) R.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

/// Rotation R (det R = +1) of the polar decomposition F = R S, S symmetric.
Matrix3d polar_rotation(const Matrix3d& F);

double psi_corotated(const Matrix3d& F, const LameParameters& lame);
Matrix3d dpsi_corotated_dF(const Matrix3d& F, const LameParameters& lame);
/// ∂²ψ/∂F² on column-major vec(F) (9 × 9), including the derivative of R.
Matrix9d d2psi_corotated_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
