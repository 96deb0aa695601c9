#include "strata/core/fem/isotropic_stress.hpp"

#include <cmath>

namespace strata {

Vector6d to_voigt(const Matrix3d& s) {
  Vector6d voigt;
  voigt << s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(1, 2), s(0, 2);
  return voigt;
}

Matrix3d from_voigt(const Vector6d& v) {
  Matrix3d s;
  s << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
  return s;
}

Matrix6d isotropic_voigt_matrix(double E, double nu) {
  Matrix6d C = Matrix6d::Zero();
  C.topLeftCorner<3, 3>().setConstant(nu);
  C.topLeftCorner<3, 3>().diagonal().setConstant(1.0 - nu);
  C.bottomRightCorner<3, 3>().diagonal().setConstant(1.0 - 2.0 * nu);
  return E / ((1.0 + nu) * (1.0 - 2.0 * nu)) * C;
}

Matrix3d isotropic_voigt_stress(const Matrix3d& strain, double E, double nu) {
  return from_voigt(isotropic_voigt_matrix(E, nu) * to_voigt(strain));
}

double von_mises_stress(const Matrix3d& sigma) {
  const Matrix3d deviator = sigma - sigma.trace() / 3.0 * Matrix3d::Identity();
  return std::sqrt(1.5 * deviator.squaredNorm());
}

}  // namespace strata
