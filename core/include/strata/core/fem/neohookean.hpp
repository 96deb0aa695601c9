#pragma once
/// \file neohookean.hpp
/// Stable neo-Hookean (Smith, de Goes, Kim, "Stable Neo-Hookean Flesh Simulation", TOG 2018):
/// ψ(F) = μ'/2 (I_C − 3) + λ'/2 (J − α)² − μ'/2 log(I_C + 1), I_C = ‖F‖², J = det F,
/// α = 1 + 3μ'/(4λ'), with μ' = 4μ/3, λ' = λ + 5μ/6 (same small-strain response as the Lamé μ, λ).
/// Defined and smooth for inverted elements (J ≤ 0).
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

double psi_neohookean(const Matrix3d& F, const LameParameters& lame);
Matrix3d dpsi_neohookean_dF(const Matrix3d& F, const LameParameters& lame);
Matrix9d d2psi_neohookean_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
