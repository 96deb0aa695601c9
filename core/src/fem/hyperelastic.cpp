#include "strata/core/fem/hyperelastic.hpp"

namespace strata {

double psi(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  switch (model) {
    case MaterialModel::stvk:
      return psi_stvk(F, lame);
    case MaterialModel::corotated:
      return psi_corotated(F, lame);
    case MaterialModel::neohookean:
      return psi_neohookean(F, lame);
  }
  return 0.0;
}

Matrix3d dpsi_dF(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  switch (model) {
    case MaterialModel::stvk:
      return dpsi_stvk_dF(F, lame);
    case MaterialModel::corotated:
      return dpsi_corotated_dF(F, lame);
    case MaterialModel::neohookean:
      return dpsi_neohookean_dF(F, lame);
  }
  return Matrix3d::Zero();
}

Matrix9d d2psi_dF2(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  switch (model) {
    case MaterialModel::stvk:
      return d2psi_stvk_dF2(F, lame);
    case MaterialModel::corotated:
      return d2psi_corotated_dF2(F, lame);
    case MaterialModel::neohookean:
      return d2psi_neohookean_dF2(F, lame);
  }
  return Matrix9d::Zero();
}

}  // namespace strata
