#pragma once
/// \file stvk.hpp
/// St. Venant–Kirchhoff energy density and derivatives:
/// ψ(F) = μ ‖E‖²_F + λ/2 tr(E)², S = λ tr(E) I + 2μ E (second Piola, the lecture's stress of the
/// Green strain), P = F S.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

double psi_stvk(const Matrix3d& F, const LameParameters& lame);
/// Second Piola–Kirchhoff stress S = λ tr(E) I + 2μ E.
Matrix3d second_piola_stvk(const Matrix3d& F, const LameParameters& lame);
/// First Piola–Kirchhoff stress P = ∂ψ/∂F = F S.
Matrix3d dpsi_stvk_dF(const Matrix3d& F, const LameParameters& lame);
/// ∂²ψ/∂F² acting on column-major vec(F) (9 × 9, symmetric).
Matrix9d d2psi_stvk_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
