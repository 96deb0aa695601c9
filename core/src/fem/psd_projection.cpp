#include "strata/core/fem/psd_projection.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace strata {

template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A) {
  const Eigen::Matrix<double, N, N> symmetric = 0.5 * (A + A.transpose());
  // Fast path: a Cholesky factorisation of A + εI succeeds only when A is (numerically) PSD.
  const double shift = 1e-12 * std::max(symmetric.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  Eigen::LLT<Eigen::Matrix<double, N, N>> cholesky(symmetric +
                                                   shift * Eigen::Matrix<double, N, N>::Identity());
  if (cholesky.info() == Eigen::Success) return symmetric;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eigen(symmetric);
  if (eigen.eigenvalues().minCoeff() >= 0.0) return symmetric;
  const Eigen::Matrix<double, N, 1> clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

template Matrix9d project_to_psd<9>(const Matrix9d&);
template Matrix12d project_to_psd<12>(const Matrix12d&);

}  // namespace strata
