#include "strata/core/fem/neohookean.hpp"

#include <cmath>

namespace strata {

namespace {

Matrix3d cross_matrix(const Vector3d& v) {
  Matrix3d m;
  m << 0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0;
  return m;
}

}  // namespace

Matrix9d d2psi_neohookean_dF2(const Matrix3d& F, const LameParameters& lame) {
  const NeoHookeanConstants k = neohookean_constants(lame);
  const double Ic = F.squaredNorm();
  const double J = F.determinant();
  const Vector9d f = Eigen::Map<const Vector9d>(F.data());
  const Matrix3d cofactor = cofactor_matrix(F);
  const Vector9d g = Eigen::Map<const Vector9d>(cofactor.data());

  Matrix9d hessian = k.mu * (1.0 - 1.0 / (Ic + 1.0)) * Matrix9d::Identity();
  hessian += 2.0 * k.mu / ((Ic + 1.0) * (Ic + 1.0)) * f * f.transpose();
  hessian += k.lambda * g * g.transpose();
  // Hessian of J = f0 · (f1 × f2), blocks (column index pairs) of cross-product matrices.
  const double scale = k.lambda * (J - k.alpha);
  const Matrix3d f0 = cross_matrix(F.col(0)), f1 = cross_matrix(F.col(1)),
                 f2 = cross_matrix(F.col(2));
  hessian.block<3, 3>(0, 3) += scale * -f2;
  hessian.block<3, 3>(3, 0) += scale * f2;
  hessian.block<3, 3>(0, 6) += scale * f1;
  hessian.block<3, 3>(6, 0) += scale * -f1;
  hessian.block<3, 3>(3, 6) += scale * -f0;
  hessian.block<3, 3>(6, 3) += scale * f0;
  return hessian;
}

}  // namespace strata
