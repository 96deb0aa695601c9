#include "strata/core/fem/psd_projection.hpp"

#include <Eigen/Eigenvalues>

namespace strata {

template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A) {
  const Eigen::Matrix<double, N, N> symmetric = 0.5 * (A + A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eigen(symmetric);
  if (eigen.eigenvalues().minCoeff() >= 0.0) return symmetric;
  const Eigen::Matrix<double, N, 1> clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

template Matrix9d project_to_psd<9>(const Matrix9d&);
template Matrix12d project_to_psd<12>(const Matrix12d&);

}  // namespace strata
