// Physical invariants of the element: rigid motions, balance of forces and torques, the lecture's
// Voigt stress and face-force recipe, and the small-strain limit of every material.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "fem_test_utils.hpp"
#include "strata/core/fem/deformation_gradient.hpp"
#include "strata/core/fem/face_forces.hpp"
#include "strata/core/fem/green_strain.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/isotropic_stress.hpp"
#include "strata/core/fem/psd_projection.hpp"
#include "strata/core/fem/tet_element.hpp"

namespace strata {
namespace {

using testing::kAllModels;
using testing::random_deformation_gradient;
using testing::random_rotation;
using testing::test_lame;

struct RestTet {
  Matrix3x4d X;
  Matrix3d Dm_inv;
  double volume;
};

RestTet irregular_rest_tet() {
  RestTet tet;
  tet.X << 0.0, 1.0, 0.2, 0.1, 0.0, 0.1, 0.9, 0.3, 0.0, 0.05, 0.1, 1.1;
  const Matrix3d Dm = edge_matrix(tet.X);
  tet.Dm_inv = Dm.inverse();
  tet.volume = Dm.determinant() / 6.0;
  return tet;
}

Vector12d as_vector(const Matrix3x4d& x) {
  return Eigen::Map<const Vector12d>(x.data());
}

class ElementInvariants : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(ElementInvariants, RigidMotionGivesZeroStrainEnergyAndForce) {
  std::mt19937 rng(1);
  const RestTet rest = irregular_rest_tet();
  for (int trial = 0; trial < 10; ++trial) {
    const Matrix3d R = random_rotation(rng);
    const Vector3d translation(0.3 * trial, -1.0, 2.0);
    const Matrix3x4d x = (R * rest.X).colwise() + translation;
    const Matrix3d F = deformation_gradient(x, rest.Dm_inv);
    EXPECT_LT(green_strain(F).norm(), 1e-14);
    EXPECT_NEAR(tet_energy(GetParam(), test_lame(), as_vector(x), rest.Dm_inv, rest.volume), 0.0,
                1e-6);  // [J] against a stiffness of 1e6 Pa: relative 1e-12
    const Vector12d g =
        tet_gradient(GetParam(), test_lame(), as_vector(x), rest.Dm_inv, rest.volume);
    EXPECT_LT(g.norm(), 1e-8 * test_lame().mu * rest.volume);
  }
}

TEST_P(ElementInvariants, ForcesSumToZeroWithZeroNetTorque) {
  std::mt19937 rng(2);
  const RestTet rest = irregular_rest_tet();
  for (int trial = 0; trial < 10; ++trial) {
    const Matrix3x4d x = random_deformation_gradient(rng, 0.3) * rest.X;
    const Vector12d f =
        -tet_gradient(GetParam(), test_lame(), as_vector(x), rest.Dm_inv, rest.volume);
    Vector3d total = Vector3d::Zero(), torque = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      total += f.segment<3>(3 * k);
      torque += x.col(k).cross(f.segment<3>(3 * k));
    }
    const double scale = f.norm() * (1.0 + x.norm());
    EXPECT_LT(total.norm(), 1e-12 * scale);
    EXPECT_LT(torque.norm(), 1e-12 * scale);
  }
}

TEST_P(ElementInvariants, FaceTractionForcesEqualEnergyGradientForces) {
  std::mt19937 rng(4);
  const RestTet rest = irregular_rest_tet();
  for (int trial = 0; trial < 10; ++trial) {
    const Matrix3x4d x = random_deformation_gradient(rng, 0.3) * rest.X;
    const Matrix3d F = deformation_gradient(x, rest.Dm_inv);
    const Matrix3d sigma = cauchy_stress(dpsi_dF(GetParam(), F, test_lame()), F);
    const Matrix3x4d face = tet_face_forces(x, sigma);
    const Vector12d gradient_forces =
        -tet_gradient(GetParam(), test_lame(), as_vector(x), rest.Dm_inv, rest.volume);
    EXPECT_LT((as_vector(face) - gradient_forces).norm(), 1e-10 * gradient_forces.norm());
  }
}

TEST_P(ElementInvariants, SmallStrainLimitIsLinearIsotropicElasticity) {
  // P(I + δ ∇u) ≈ λ tr(ε) I + 2μ ε with ε = sym(∇u), to first order in δ.
  std::mt19937 rng(6);
  const LameParameters lame = test_lame();
  for (int trial = 0; trial < 5; ++trial) {
    const Matrix3d grad_u = random_deformation_gradient(rng, 1.0) - Matrix3d::Identity();
    const double delta = 1e-6;
    const Matrix3d P = dpsi_dF(GetParam(), Matrix3d::Identity() + delta * grad_u, lame) / delta;
    const Matrix3d epsilon = 0.5 * (grad_u + grad_u.transpose());
    const Matrix3d linear =
        lame.lambda * epsilon.trace() * Matrix3d::Identity() + 2 * lame.mu * epsilon;
    EXPECT_LT((P - linear).norm(), 1e-5 * linear.norm());
  }
}

TEST_P(ElementInvariants, ProjectedHessianIsPositiveSemiDefinite) {
  std::mt19937 rng(8);
  const RestTet rest = irregular_rest_tet();
  for (int trial = 0; trial < 10; ++trial) {
    Matrix3d F = random_deformation_gradient(rng, 0.8);
    const Matrix3x4d x = F * rest.X;
    const Matrix12d H =
        tet_hessian(GetParam(), test_lame(), as_vector(x), rest.Dm_inv, rest.volume, true);
    Eigen::SelfAdjointEigenSolver<Matrix12d> eigen(H);
    EXPECT_GT(eigen.eigenvalues().minCoeff(), -1e-9 * eigen.eigenvalues().cwiseAbs().maxCoeff());
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, ElementInvariants, ::testing::ValuesIn(kAllModels),
                         [](const auto& info) { return to_string(info.param); });

TEST(IsotropicStress, VoigtFormEqualsTensorForm) {
  std::mt19937 rng(9);
  for (double nu : {0.0, 0.25, 0.3, 0.45, 0.49}) {
    const double E = 2.0e9;
    const LameParameters lame = lame_parameters(E, nu);
    for (int trial = 0; trial < 5; ++trial) {
      const Matrix3d F = random_deformation_gradient(rng, 0.2);
      const Matrix3d strain = green_strain(F);
      const Matrix3d tensor =
          lame.lambda * strain.trace() * Matrix3d::Identity() + 2.0 * lame.mu * strain;
      EXPECT_LT((isotropic_voigt_stress(strain, E, nu) - tensor).norm(), 1e-12 * tensor.norm());
      EXPECT_LT((second_piola_stvk(F, lame) - tensor).norm(), 1e-12 * tensor.norm());
    }
  }
}

TEST(IsotropicStress, VoigtRoundTripAndVonMises) {
  Vector6d voigt;
  voigt << 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(to_voigt(from_voigt(voigt)), voigt);
  // Uniaxial stress: von Mises equals the axial stress; hydrostatic: zero.
  Matrix3d uniaxial = Matrix3d::Zero();
  uniaxial(0, 0) = 7.0;
  EXPECT_NEAR(von_mises_stress(uniaxial), 7.0, 1e-14);
  EXPECT_NEAR(von_mises_stress(3.0 * Matrix3d::Identity()), 0.0, 1e-14);
  // Pure shear τ: √3 τ.
  Matrix3d shear = Matrix3d::Zero();
  shear(0, 1) = shear(1, 0) = 2.0;
  EXPECT_NEAR(von_mises_stress(shear), 2.0 * std::sqrt(3.0), 1e-14);
}

TEST(IsotropicStress, LameParametersFromYoungAndPoisson) {
  const LameParameters lame = lame_parameters(210e9, 0.3);
  EXPECT_NEAR(lame.mu, 210e9 / 2.6, 1e-3);
  EXPECT_NEAR(lame.lambda, 210e9 * 0.3 / (1.3 * 0.4), 1e-3);
}

}  // namespace
}  // namespace strata
