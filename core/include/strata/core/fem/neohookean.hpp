#pragma once
/// \file neohookean.hpp
/// Stable neo-Hookean (Smith, de Goes, Kim, "Stable Neo-Hookean Flesh Simulation", TOG 2018):
/// ψ(F) = μ'/2 (I_C − 3) + λ'/2 (J − α)² − μ'/2 log(I_C + 1), I_C = ‖F‖², J = det F,
/// α = 1 + 3μ'/(4λ'), with μ' = 4μ/3, λ' = λ + 5μ/6 (same small-strain response as the Lamé μ, λ),
/// shifted by a constant so that ψ(I) = 0.
/// Defined and smooth for inverted elements (J ≤ 0).
#include <cmath>

#include <Eigen/LU>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

/// The constants μ', λ', α of the energy from the Lamé parameters.
struct NeoHookeanConstants {
  double mu, lambda, alpha;
};
inline NeoHookeanConstants neohookean_constants(const LameParameters& lame) {
  const double mu = 4.0 / 3.0 * lame.mu;
  const double lambda = lame.lambda + 5.0 / 6.0 * lame.mu;
  return {mu, lambda, 1.0 + 0.75 * mu / lambda};
}

/// ∂J/∂F = cofactor matrix of F (columns f1×f2, f2×f0, f0×f1).
inline Matrix3d cofactor_matrix(const Matrix3d& F) {
  Matrix3d cofactor;
  cofactor.col(0) = F.col(1).cross(F.col(2));
  cofactor.col(1) = F.col(2).cross(F.col(0));
  cofactor.col(2) = F.col(0).cross(F.col(1));
  return cofactor;
}

inline double psi_neohookean(const Matrix3d& F, const LameParameters& lame) {
  const NeoHookeanConstants k = neohookean_constants(lame);
  const double Ic = F.squaredNorm();
  const double J = F.determinant();
  // The constant makes ψ(I) = 0 (the paper's form is not zero at rest; forces are unaffected).
  const double rest =
      0.5 * k.lambda * (1.0 - k.alpha) * (1.0 - k.alpha) - 0.5 * k.mu * std::log(4.0);
  return 0.5 * k.mu * (Ic - 3.0) + 0.5 * k.lambda * (J - k.alpha) * (J - k.alpha) -
         0.5 * k.mu * std::log(Ic + 1.0) - rest;
}

inline Matrix3d dpsi_neohookean_dF(const Matrix3d& F, const LameParameters& lame) {
  const NeoHookeanConstants k = neohookean_constants(lame);
  const double Ic = F.squaredNorm();
  const double J = F.determinant();
  return k.mu * (1.0 - 1.0 / (Ic + 1.0)) * F + k.lambda * (J - k.alpha) * cofactor_matrix(F);
}

Matrix9d d2psi_neohookean_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
