#include "strata/core/fem/stvk.hpp"

namespace strata {

Matrix9d d2psi_stvk_dF2(const Matrix3d& F, const LameParameters& lame) {
  const Matrix3d S = second_piola_stvk(F, lame);
  Matrix9d hessian;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      Matrix3d dF = Matrix3d::Zero();
      dF(r, c) = 1.0;
      const Matrix3d dE = 0.5 * (dF.transpose() * F + F.transpose() * dF);
      const Matrix3d dS = lame.lambda * dE.trace() * Matrix3d::Identity() + 2.0 * lame.mu * dE;
      const Matrix3d dP = dF * S + F * dS;
      hessian.col(3 * c + r) = Eigen::Map<const Vector9d>(dP.data());
    }
  return hessian;
}

}  // namespace strata
