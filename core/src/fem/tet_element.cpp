#include "strata/core/fem/tet_element.hpp"

#include "strata/core/fem/deformation_gradient.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/isotropic_hessian.hpp"

namespace strata {

double tet_energy(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                  const Matrix3d& Dm_inv, double rest_volume) {
  return rest_volume * psi(model, deformation_gradient(tet_positions(x), Dm_inv), lame);
}

Vector12d tet_gradient(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                       const Matrix3d& Dm_inv, double rest_volume) {
  const Matrix3d P = dpsi_dF(model, deformation_gradient(tet_positions(x), Dm_inv), lame);
  // ∂W/∂x_k = V · P ∇N_k
  const Eigen::Matrix<double, 4, 3> grad_N = shape_function_gradients(Dm_inv);
  Vector12d gradient;
  for (int k = 0; k < 4; ++k)
    gradient.segment<3>(3 * k) = rest_volume * P * grad_N.row(k).transpose();
  return gradient;
}

Matrix12d tet_hessian(MaterialModel model, const LameParameters& lame, const Vector12d& x,
                      const Matrix3d& Dm_inv, double rest_volume, bool project_psd) {
  const Matrix3d F = deformation_gradient(tet_positions(x), Dm_inv);
  const Matrix9d d2psi = project_psd ? d2psi_dF2_psd(model, F, lame) : d2psi_dF2(model, F, lame);
  const Eigen::Matrix<double, 9, 12> dF_dx = deformation_gradient_jacobian(Dm_inv);
  return rest_volume * dF_dx.transpose() * d2psi * dF_dx;
}

}  // namespace strata
