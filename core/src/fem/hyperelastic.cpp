#include "strata/core/fem/hyperelastic.hpp"

#include "strata/core/fem/material_registry.hpp"

namespace strata {

double psi(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  return material_traits(model).energy_density(F, lame);
}

Matrix3d dpsi_dF(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  return material_traits(model).first_piola(F, lame);
}

Matrix9d d2psi_dF2(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  return material_traits(model).hessian(F, lame);
}

}  // namespace strata
