// Rotation-variant SVD / polar rotation (polar_decomposition.hpp): structural properties on 10k
// deformation gradients of every difficult kind, and agreement with an independent reference built
// on Eigen::JacobiSVD (signs fixed as in Irving, Teran, Fedkiw 2004).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "strata/core/fem/corotated.hpp"
#include "strata/core/fem/polar_decomposition.hpp"

namespace strata {
namespace {

RotationVariantSvd reference_svd(const Matrix3d& F) {
  Eigen::JacobiSVD<Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  RotationVariantSvd result{svd.matrixU(), svd.singularValues(), svd.matrixV()};
  if (result.U.determinant() < 0.0) {
    result.U.col(2) *= -1.0;
    result.sigma[2] *= -1.0;
  }
  if (result.V.determinant() < 0.0) {
    result.V.col(2) *= -1.0;
    result.sigma[2] *= -1.0;
  }
  return result;
}

Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

Matrix3d from_singular_values(std::mt19937& rng, const Vector3d& sigma) {
  return random_rotation(rng) * sigma.asDiagonal() * random_rotation(rng).transpose();
}

/// Deformation gradient of kind `kind` (0 … kNumKinds − 1), before scaling.
constexpr int kNumKinds = 18;
Matrix3d sample_kind(std::mt19937& rng, int kind) {
  std::uniform_real_distribution<double> uniform(0.5, 2.0);
  std::normal_distribution<double> normal;
  auto gaussian = [&] {
    Matrix3d M;
    for (int i = 0; i < 9; ++i)
      M.data()[i] = normal(rng);
    return M;
  };
  const Matrix3d reflection = Vector3d(1.0, 1.0, -1.0).asDiagonal();
  switch (kind) {
    case 0:  // well-conditioned
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), uniform(rng)));
    case 1:  // inverted, well-conditioned
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), -uniform(rng)));
    case 2:  // general Gaussian entries (both orientations)
      return gaussian();
    case 3:  // near-singular
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), 1e-9 * uniform(rng)));
    case 4:  // near-singular and inverted
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), -1e-9 * uniform(rng)));
    case 5:  // repeated largest singular value
      return from_singular_values(rng, Vector3d(2.0, 2.0, 0.5));
    case 6:  // repeated smallest singular value, inverted
      return from_singular_values(rng, Vector3d(2.0, 0.5, -0.5));
    case 7:  // nearly repeated
      return from_singular_values(rng, Vector3d(1.0, 1.0 + 1e-9 * normal(rng), 0.7));
    case 8:  // identity
      return Matrix3d::Identity();
    case 9:  // pure rotation
      return random_rotation(rng);
    case 10:  // near-identity
      return Matrix3d::Identity() + 1e-8 * gaussian();
    case 11:  // reflection of a rotation (|σ| all 1)
      return random_rotation(rng) * reflection * random_rotation(rng);
    case 12:  // reflection of a stretch
      return reflection *
             from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), uniform(rng)));
    case 13: {  // rank 1
      const Vector3d a = Vector3d::Random(), b = Vector3d::Random();
      return a * b.transpose();
    }
    case 14:  // rank 2, up to round-off of the product
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), 0.0));
    case 16:  // graded singular values, det > 0 (Newton path with scaling)
      return from_singular_values(rng, uniform(rng) * Vector3d(1.0, 1e-2, 1e-4));
    case 17:  // one small singular value, det > 0 (Newton path with scaling)
      return from_singular_values(rng, Vector3d(uniform(rng), uniform(rng), 1e-5 * uniform(rng)));
    default: {  // rank 2 exactly: third column the sum of the first two
      Matrix3d M = gaussian();
      M.col(2) = M.col(0) + M.col(1);
      return M;
    }
  }
}

/// Largest error of each kind over all samples, relative to the scale named in the test.
struct MaxErrors {
  double orthonormality = 0, reconstruction = 0, sigma = 0, rotation = 0, symmetry = 0;
};

void check_decomposition(const Matrix3d& F, MaxErrors& errors) {
  const RotationVariantSvd svd = rotation_variant_svd(F);
  const RotationVariantSvd ref = reference_svd(F);
  const Vector3d& s = svd.sigma;
  const double scale = ref.sigma[0];

  ASSERT_TRUE(svd.U.allFinite() && svd.V.allFinite() && s.allFinite()) << F;
  const double orthonormality = std::max((svd.U.transpose() * svd.U - Matrix3d::Identity()).norm(),
                                         (svd.V.transpose() * svd.V - Matrix3d::Identity()).norm());
  EXPECT_LT(orthonormality, 1e-14) << F;
  EXPECT_GT(svd.U.determinant(), 0.0) << F;
  EXPECT_GT(svd.V.determinant(), 0.0) << F;
  errors.orthonormality = std::max(errors.orthonormality, orthonormality);

  const double reconstruction = (F - svd.U * s.asDiagonal() * svd.V.transpose()).norm() / F.norm();
  EXPECT_LT(reconstruction, 1e-14) << F;
  errors.reconstruction = std::max(errors.reconstruction, reconstruction);

  EXPECT_GE(s[0], s[1]) << F;
  EXPECT_GE(s[1], std::abs(s[2])) << F;
  EXPECT_GE(s[1], 0.0) << F;
  const double det = F.determinant();
  const double det_round_off = 1e-13 * scale * scale * scale;
  if (det > det_round_off) {
    EXPECT_GE(s[2], 0.0) << F;
  }
  if (det < -det_round_off) {
    EXPECT_LT(s[2], 0.0) << F;
  }

  const double sigma_error = (s - ref.sigma).cwiseAbs().maxCoeff() / scale;
  EXPECT_LT(sigma_error, 1e-14) << F;
  errors.sigma = std::max(errors.sigma, sigma_error);

  // R is unique iff every σᵢ + σⱼ ≠ 0 (i ≠ j); its condition number is σ₀ / min(σᵢ + σⱼ).
  // Both the SVD's U Vᵀ and polar_rotation (Newton fast path for det F > 0) are checked.
  const double pair_sum = std::min(
      {ref.sigma[0] + ref.sigma[1], ref.sigma[0] + ref.sigma[2], ref.sigma[1] + ref.sigma[2]});
  for (const Matrix3d& R : {Matrix3d(svd.U * svd.V.transpose()), polar_rotation(F)}) {
    EXPECT_LT((R.transpose() * R - Matrix3d::Identity()).norm(), 1e-14) << F;
    EXPECT_GT(R.determinant(), 0.0) << F;
    if (pair_sum > 1e-6 * scale) {
      const double rotation_error = (R - ref.U * ref.V.transpose()).norm() * pair_sum / scale;
      EXPECT_LT(rotation_error, 1e-14) << F;
      errors.rotation = std::max(errors.rotation, rotation_error);
    }
    // Whether unique or not: RᵀF = S is symmetric with trace Σσ.
    const Matrix3d S = R.transpose() * F;
    const double symmetry = (S - S.transpose()).norm() / scale;
    EXPECT_LT(symmetry, 1e-14) << F;
    EXPECT_NEAR(S.trace(), s.sum(), 1e-14 * scale) << F;
    errors.symmetry = std::max(errors.symmetry, symmetry);
  }
}

TEST(PolarDecomposition, PropertiesAndAgreementWithJacobiSvdOn10kMatrices) {
  std::mt19937 rng(2004);
  const double scales[] = {1.0, 1e-8, 1e8};
  MaxErrors errors;
  for (int sample = 0; sample < 10000; ++sample) {
    const int kind = sample % kNumKinds;
    const double scale = scales[(sample / kNumKinds) % 3];
    SCOPED_TRACE("sample " + std::to_string(sample) + " kind " + std::to_string(kind));
    check_decomposition(scale * sample_kind(rng, kind), errors);
    if (HasFailure()) break;
  }
  std::printf(
      "max errors: orthonormality %.2g, reconstruction %.2g, sigma %.2g, rotation×cond %.2g, "
      "symmetry %.2g\n",
      errors.orthonormality, errors.reconstruction, errors.sigma, errors.rotation, errors.symmetry);
}

TEST(PolarDecomposition, DiagonalAndPermutedInputsAreExact) {
  const Matrix3d D = Vector3d(0.5, 3.0, 2.0).asDiagonal();
  const RotationVariantSvd svd = rotation_variant_svd(D);
  EXPECT_EQ(svd.sigma, Vector3d(3.0, 2.0, 0.5));
  EXPECT_LT((polar_rotation(D) - Matrix3d::Identity()).norm(), 1e-15);

  const Matrix3d inverted = Vector3d(2.0, -1.0, 3.0).asDiagonal();
  const RotationVariantSvd inv = rotation_variant_svd(inverted);
  EXPECT_EQ(inv.sigma, Vector3d(3.0, 2.0, -1.0));
  // The inverted direction keeps R = I: S = diag(2, −1, 3).
  EXPECT_LT((polar_rotation(inverted) - Matrix3d::Identity()).norm(), 1e-15);
}

TEST(PolarDecomposition, ZeroMatrixAndNonFiniteInput) {
  const RotationVariantSvd zero = rotation_variant_svd(Matrix3d::Zero());
  EXPECT_EQ(zero.sigma, Vector3d::Zero());
  EXPECT_EQ(polar_rotation(Matrix3d::Zero()), Matrix3d::Identity());

  Matrix3d F = Matrix3d::Identity();
  F(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(rotation_variant_svd(F).sigma.allFinite());
  F(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(rotation_variant_svd(F).sigma.allFinite());
}

TEST(PolarDecomposition, CorotatedEnergyAndStressMatchJacobiSvdReference) {
  std::mt19937 rng(17);
  const LameParameters lame{0.3, 1.1};
  for (int sample = 0; sample < 200; ++sample) {
    const Matrix3d F = sample_kind(rng, sample % 2);  // well-conditioned, upright and inverted
    const RotationVariantSvd ref = reference_svd(F);
    const Matrix3d R = ref.U * ref.V.transpose();
    const double trace_term = (R.transpose() * F).trace() - 3.0;
    const double psi =
        lame.mu * (F - R).squaredNorm() + 0.5 * lame.lambda * trace_term * trace_term;
    const Matrix3d P = 2.0 * lame.mu * (F - R) + lame.lambda * trace_term * R;
    EXPECT_NEAR(psi_corotated(F, lame), psi, 1e-13 * (1.0 + std::abs(psi)));
    EXPECT_LT((dpsi_corotated_dF(F, lame) - P).norm(), 1e-13 * (1.0 + P.norm()));
  }
}

}  // namespace
}  // namespace strata
