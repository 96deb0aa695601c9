#pragma once
/// \file tet_element.hpp
/// Element level: energy, gradient and Hessian of one linear tet,
/// W(x) = V · ψ(F(x)), ∂W/∂x = V · (∂F/∂x)ᵀ vec(P), ∂²W/∂x² = V · (∂F/∂x)ᵀ (∂²ψ/∂F²) (∂F/∂x).
/// x is the 12-vector (x0, x1, x2, x3); the elastic force on the vertices is −∂W/∂x.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

/// Positions of a tet's four vertices as 3 × 4 columns, from a 12-vector (x0, x1, x2, x3).
inline Matrix3x4d tet_positions(const Vector12d& x) {
  return Eigen::Map<const Matrix3x4d>(x.data());
}

double tet_energy(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                  const Matrix3d& Dm_inv, double rest_volume);
Vector12d tet_gradient(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                       const Matrix3d& Dm_inv, double rest_volume);
/// Hessian; if `project_psd`, ∂²ψ/∂F² is first projected onto the PSD cone (so the result is PSD).
Matrix12d tet_hessian(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                      const Matrix3d& Dm_inv, double rest_volume, bool project_psd = false);

}  // namespace strata
