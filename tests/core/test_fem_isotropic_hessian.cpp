// Singular-value-frame Hessian and closed-form PSD projection (isotropic_hessian.hpp) against the
// direct ∂²ψ/∂F² formulas and the eigen-solve projection project_to_psd<9>, for every material at
// random, strongly compressed, inverted and near-degenerate deformation gradients, and at mesh
// level.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "fem_test_utils.hpp"
#include "strata/core/fem/deformation_gradient.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/isotropic_hessian.hpp"
#include "strata/core/fem/psd_projection.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

using testing::kAllModels;
using testing::random_deformation_gradient;
using testing::random_rotation;
using testing::test_lame;

Matrix3d with_singular_values(std::mt19937& rng, const Vector3d& sigma) {
  return random_rotation(rng) * sigma.asDiagonal() * random_rotation(rng).transpose();
}

/// Deformation gradients of every kind: moderate and large random ones, strong compression,
/// inversion, (nearly) equal singular values, nearly flat and rank-deficient ones, and rotations.
std::vector<Matrix3d> test_deformation_gradients() {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> uniform(0.3, 1.8);
  std::vector<Matrix3d> Fs;
  for (int trial = 0; trial < 20; ++trial) {
    Fs.push_back(random_deformation_gradient(rng, 0.3));
    Fs.push_back(random_deformation_gradient(rng, 0.9));  // some of these are inverted
    Fs.push_back(with_singular_values(rng, Vector3d(uniform(rng), uniform(rng), uniform(rng))));
    Fs.push_back(with_singular_values(rng, Vector3d(uniform(rng), uniform(rng), -uniform(rng))));
    Fs.push_back(with_singular_values(rng, Vector3d(0.5, 0.6, 0.7) * uniform(rng)));
  }
  const std::vector<Vector3d> special = {
      {1.0, 1.0, 1.0},          {1.2, 1.2 + 1e-9, 0.9}, {0.8, 0.8, 0.8},
      {0.6, 0.6, -0.6},         {1.5, 1e-7, 1e-8},      {1.3, 0.9, 0.0},
      {0.7, 0.7 + 1e-12, -0.7}, {2.0, 0.4, -1e-6},      {1.1, 1.0, -0.999999}};
  for (const Vector3d& sigma : special)
    for (int k = 0; k < 3; ++k)
      Fs.push_back(with_singular_values(rng, sigma));
  Fs.push_back(Matrix3d::Identity());
  Fs.push_back(random_rotation(rng));
  return Fs;
}

class IsotropicHessian : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(IsotropicHessian, FrameFormRebuildsTheDirectHessian) {
  const LameParameters lame = test_lame();
  for (const Matrix3d& F : test_deformation_gradients()) {
    const Matrix9d direct = d2psi_dF2(GetParam(), F, lame);
    const Matrix9d frame = frame_hessian_matrix(singular_frame_hessian(GetParam(), F, lame), false);
    EXPECT_LT((frame - direct).norm(), 1e-11 * direct.norm()) << "F =\n" << F;
  }
}

TEST_P(IsotropicHessian, ClosedFormProjectionEqualsEigenSolveProjection) {
  const LameParameters lame = test_lame();
  int indefinite = 0;
  for (const Matrix3d& F : test_deformation_gradients()) {
    const Matrix9d direct = d2psi_dF2(GetParam(), F, lame);
    const Matrix9d reference = project_to_psd<9>(direct);
    const Matrix9d projected = d2psi_dF2_psd(GetParam(), F, lame);
    EXPECT_LT((projected - reference).norm(), 1e-10 * direct.norm()) << "F =\n" << F;
    EXPECT_LT((projected - projected.transpose()).norm(), 1e-12 * direct.norm());
    const Eigen::SelfAdjointEigenSolver<Matrix9d> eigen(direct);
    if (eigen.eigenvalues().minCoeff() < -1e-6 * direct.norm()) ++indefinite;
  }
  // Not vacuous: the projection has work to do on a good share of the states.
  EXPECT_GE(indefinite, 20);
}

TEST_P(IsotropicHessian, ProjectionIsPositiveSemiDefiniteAndKeepsPsdHessians) {
  const LameParameters lame = test_lame();
  for (const Matrix3d& F : test_deformation_gradients()) {
    const Matrix9d projected = d2psi_dF2_psd(GetParam(), F, lame);
    const Eigen::SelfAdjointEigenSolver<Matrix9d> eigen(projected);
    EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-12 * projected.norm()) << "F =\n" << F;
  }
  // Pure stretch by 10 %: every model's Hessian is positive definite there and stays unchanged.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const Matrix3d F = with_singular_values(rng, Vector3d(1.1, 1.1, 1.1));
    const Matrix9d direct = d2psi_dF2(GetParam(), F, lame);
    ASSERT_GT(Eigen::SelfAdjointEigenSolver<Matrix9d>(direct).eigenvalues().minCoeff(), 0.0);
    EXPECT_LT((d2psi_dF2_psd(GetParam(), F, lame) - direct).norm(), 1e-12 * direct.norm());
  }
}

TEST_P(IsotropicHessian, ProjectedMeshStiffnessEqualsAssemblyOfEigenSolveProjections) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 1.0), {3, 3, 3});
  Material material;
  material.model = GetParam();
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.35;
  const ElasticModel model(mesh.vertices, mesh.tets, material);
  // Compressed by 35 % along z and randomly perturbed: many elements are indefinite.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.06, 0.06);
  VectorXd x = model.rest_positions();
  for (Index v = 0; v < model.num_vertices(); ++v) {
    x[3 * v + 2] *= 0.65;
    for (int k = 0; k < 3; ++k)
      x[3 * v + k] += jitter(rng);
  }
  SparseMatrixd K_psd, K_raw;
  model.stiffness(x, K_psd, true);
  model.stiffness(x, K_raw, false);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(K_psd);

  Eigen::MatrixXd reference = Eigen::MatrixXd::Zero(x.size(), x.size());
  const LameParameters lame = material.lame();
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const Matrix3d& Dm_inv = model.rest_data().Dm_inv[t];
    Matrix3x4d xt;
    for (int k = 0; k < 4; ++k)
      xt.col(k) = x.segment<3>(3 * mesh.tets(t, k));
    const Matrix3d F = deformation_gradient(xt, Dm_inv);
    const Eigen::Matrix<double, 9, 12> B = deformation_gradient_jacobian(Dm_inv);
    const Matrix12d H = model.rest_data().rest_volume[t] * B.transpose() *
                        project_to_psd<9>(d2psi_dF2(GetParam(), F, lame)) * B;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        reference.block<3, 3>(3 * mesh.tets(t, a), 3 * mesh.tets(t, b)) +=
            H.block<3, 3>(3 * a, 3 * b);
  }
  EXPECT_LT((dense - reference).norm(), 1e-10 * reference.norm());
  EXPECT_GT((dense - Eigen::MatrixXd(K_raw)).norm(), 1e-4 * reference.norm())
      << "the projection changed nothing: the test state is not indefinite enough";
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues().minCoeff(),
            -1e-10 * reference.norm());
}

INSTANTIATE_TEST_SUITE_P(AllModels, IsotropicHessian, ::testing::ValuesIn(kAllModels),
                         [](const auto& info) { return to_string(info.param); });

}  // namespace
}  // namespace strata
