#include "strata/core/fem/corotated.hpp"

#include <cmath>

namespace strata {

namespace {

/// Division that keeps its sign and stays finite when the denominator vanishes.
double safe_divide(double numerator, double denominator) {
  constexpr double kEpsilon = 1e-12;
  if (std::abs(denominator) < kEpsilon) denominator = denominator < 0.0 ? -kEpsilon : kEpsilon;
  return numerator / denominator;
}

}  // namespace

double psi_corotated(const Matrix3d& F, const LameParameters& lame) {
  const Matrix3d R = polar_rotation(F);
  const double trace_term = R.cwiseProduct(F).sum() - 3.0;  // tr(RᵀF) − 3 = Σσ − 3
  return lame.mu * (F - R).squaredNorm() + 0.5 * lame.lambda * trace_term * trace_term;
}

Matrix3d dpsi_corotated_dF(const Matrix3d& F, const LameParameters& lame) {
  const Matrix3d R = polar_rotation(F);
  const double trace_term = R.cwiseProduct(F).sum() - 3.0;
  return 2.0 * lame.mu * (F - R) + lame.lambda * trace_term * R;
}

Matrix9d d2psi_corotated_dF2(const Matrix3d& F, const LameParameters& lame) {
  // Isotropic Hessian in the singular frame: with dF̂ = Uᵀ dF V and dP̂ = Uᵀ dP V,
  // dP̂_ii = Σ_j ψ_ij dF̂_jj and, per pair i ≠ j, [dP̂_ij; dP̂_ji] = [[a, b], [b, a]] [dF̂_ij; dF̂_ji]
  // with a + b = (ψ_i − ψ_j)/(σ_i − σ_j) and a − b = (ψ_i + ψ_j)/(σ_i + σ_j).
  const RotationVariantSvd svd = rotation_variant_svd(F);
  const Vector3d& s = svd.sigma;
  const double trace_term = s.sum() - 3.0;
  Vector3d dpsi;
  for (int i = 0; i < 3; ++i)
    dpsi[i] = 2.0 * lame.mu * (s[i] - 1.0) + lame.lambda * trace_term;
  Matrix3d d2psi = Matrix3d::Constant(lame.lambda);
  d2psi.diagonal().array() += 2.0 * lame.mu;

  Matrix3d a = Matrix3d::Zero(), b = Matrix3d::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (i == j) continue;
      const double sum_mode = 2.0 * lame.mu;  // (ψ_i − ψ_j)/(σ_i − σ_j), exact for this energy
      const double difference_mode = safe_divide(dpsi[i] + dpsi[j], s[i] + s[j]);
      a(i, j) = 0.5 * (sum_mode + difference_mode);
      b(i, j) = 0.5 * (sum_mode - difference_mode);
    }

  Matrix9d hessian;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      const Matrix3d dF_hat = svd.U.row(r).transpose() * svd.V.row(c);
      Matrix3d dP_hat;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          if (i == j)
            dP_hat(i, i) = d2psi.row(i).dot(dF_hat.diagonal());
          else
            dP_hat(i, j) = a(i, j) * dF_hat(i, j) + b(i, j) * dF_hat(j, i);
        }
      }
      const Matrix3d dP = svd.U * dP_hat * svd.V.transpose();
      hessian.col(3 * c + r) = Eigen::Map<const Vector9d>(dP.data());
    }
  return hessian;
}

}  // namespace strata
