#pragma once
/// \file stvk.hpp
/// St. Venant–Kirchhoff energy density and derivatives:
/// ψ(F) = μ ‖E‖²_F + λ/2 tr(E)², S = λ tr(E) I + 2μ E (second Piola, the lecture's stress of the
/// Green strain), P = F S.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/green_strain.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

inline double psi_stvk(const Matrix3d& F, const LameParameters& lame) {
  const Matrix3d E = green_strain(F);
  const double trace = E.trace();
  return lame.mu * E.squaredNorm() + 0.5 * lame.lambda * trace * trace;
}

/// Second Piola–Kirchhoff stress S = λ tr(E) I + 2μ E.
inline Matrix3d second_piola_stvk(const Matrix3d& F, const LameParameters& lame) {
  const Matrix3d E = green_strain(F);
  return lame.lambda * E.trace() * Matrix3d::Identity() + 2.0 * lame.mu * E;
}

/// First Piola–Kirchhoff stress P = ∂ψ/∂F = F S.
inline Matrix3d dpsi_stvk_dF(const Matrix3d& F, const LameParameters& lame) {
  return F * second_piola_stvk(F, lame);
}

/// ∂²ψ/∂F² acting on column-major vec(F) (9 × 9, symmetric).
Matrix9d d2psi_stvk_dF2(const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
