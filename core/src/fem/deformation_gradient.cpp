#include "strata/core/fem/deformation_gradient.hpp"

namespace strata {

Eigen::Matrix<double, 4, 3> shape_function_gradients(const Matrix3d& Dm_inv) {
  Eigen::Matrix<double, 4, 3> gradients;
  gradients.bottomRows<3>() = Dm_inv;
  gradients.row(0) = -Dm_inv.colwise().sum();
  return gradients;
}

Eigen::Matrix<double, 9, 12> deformation_gradient_jacobian(const Matrix3d& Dm_inv) {
  const Eigen::Matrix<double, 4, 3> grad_N = shape_function_gradients(Dm_inv);
  Eigen::Matrix<double, 9, 12> jacobian = Eigen::Matrix<double, 9, 12>::Zero();
  // F(r, c) = Σ_k x_k[r] ∇N_k[c]
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        jacobian(3 * c + r, 3 * k + r) = grad_N(k, c);
  return jacobian;
}

}  // namespace strata
