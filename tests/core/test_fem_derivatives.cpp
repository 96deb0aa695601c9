// Finite-difference checks of every material's stress against its energy and of its Hessian
// against its stress, at the density and the element level, at random deformed states.
#include <gtest/gtest.h>

#include "fem_test_utils.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/tet_element.hpp"

namespace strata {
namespace {

using testing::kAllModels;
using testing::random_deformation_gradient;
using testing::test_lame;

class MaterialDerivatives : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(MaterialDerivatives, StressMatchesCentralDifferenceOfEnergy) {
  std::mt19937 rng(7);
  const LameParameters lame = test_lame();
  for (int trial = 0; trial < 20; ++trial) {
    const Matrix3d F = random_deformation_gradient(rng, 0.4);
    const Matrix3d P = dpsi_dF(GetParam(), F, lame);
    const double h = 1e-6;
    for (int i = 0; i < 9; ++i) {
      Matrix3d plus = F, minus = F;
      plus.data()[i] += h;
      minus.data()[i] -= h;
      const double fd = (psi(GetParam(), plus, lame) - psi(GetParam(), minus, lame)) / (2 * h);
      EXPECT_NEAR(P.data()[i], fd, 1e-6 * (1.0 + P.norm())) << "trial " << trial << " entry " << i;
    }
  }
}

TEST_P(MaterialDerivatives, HessianMatchesCentralDifferenceOfStress) {
  std::mt19937 rng(11);
  const LameParameters lame = test_lame();
  for (int trial = 0; trial < 20; ++trial) {
    const Matrix3d F = random_deformation_gradient(rng, 0.4);
    const Matrix9d H = d2psi_dF2(GetParam(), F, lame);
    EXPECT_LT((H - H.transpose()).norm(), 1e-8 * H.norm()) << "Hessian not symmetric";
    const double h = 1e-6;
    for (int i = 0; i < 9; ++i) {
      Matrix3d plus = F, minus = F;
      plus.data()[i] += h;
      minus.data()[i] -= h;
      const Matrix3d fd =
          (dpsi_dF(GetParam(), plus, lame) - dpsi_dF(GetParam(), minus, lame)) / (2 * h);
      const Vector9d column = Eigen::Map<const Vector9d>(fd.data());
      EXPECT_LT((H.col(i) - column).norm(), 1e-6 * (1.0 + H.norm())) << "column " << i;
    }
  }
}

TEST_P(MaterialDerivatives, InvertedStatesForModelsThatHandleInversion) {
  if (!handles_inversion(GetParam())) GTEST_SKIP() << "model does not handle inversion";
  std::mt19937 rng(5);
  const LameParameters lame = test_lame();
  for (int trial = 0; trial < 10; ++trial) {
    Matrix3d F = random_deformation_gradient(rng, 0.3);
    F.col(0) *= -1.0;  // reflect: J < 0
    ASSERT_LT(F.determinant(), 0.0);
    const Matrix3d P = dpsi_dF(GetParam(), F, lame);
    const Matrix9d H = d2psi_dF2(GetParam(), F, lame);
    ASSERT_TRUE(P.allFinite() && H.allFinite());
    const double h = 1e-6;
    for (int i = 0; i < 9; ++i) {
      Matrix3d plus = F, minus = F;
      plus.data()[i] += h;
      minus.data()[i] -= h;
      const double fd = (psi(GetParam(), plus, lame) - psi(GetParam(), minus, lame)) / (2 * h);
      EXPECT_NEAR(P.data()[i], fd, 1e-6 * (1.0 + P.norm()));
      const Matrix3d dP =
          (dpsi_dF(GetParam(), plus, lame) - dpsi_dF(GetParam(), minus, lame)) / (2 * h);
      EXPECT_LT((H.col(i) - Eigen::Map<const Vector9d>(dP.data())).norm(), 1e-5 * (1 + H.norm()));
    }
  }
}

TEST_P(MaterialDerivatives, ElementGradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const LameParameters lame = test_lame();
  Matrix3x4d X;  // an irregular rest tet
  X << 0.0, 1.0, 0.2, 0.1, 0.0, 0.1, 0.9, 0.3, 0.0, 0.05, 0.1, 1.1;
  Matrix3d Dm;
  Dm << X.col(1) - X.col(0), X.col(2) - X.col(0), X.col(3) - X.col(0);
  const Matrix3d Dm_inv = Dm.inverse();
  const double volume = Dm.determinant() / 6.0;
  ASSERT_GT(volume, 0.0);
  for (int trial = 0; trial < 10; ++trial) {
    Vector12d x = Eigen::Map<const Vector12d>(X.data());
    for (int i = 0; i < 12; ++i)
      x[i] += 0.15 * uniform(rng);
    const Vector12d g = tet_gradient(GetParam(), lame, x, Dm_inv, volume);
    const Matrix12d H = tet_hessian(GetParam(), lame, x, Dm_inv, volume);
    const double h = 1e-6;
    for (int i = 0; i < 12; ++i) {
      Vector12d plus = x, minus = x;
      plus[i] += h;
      minus[i] -= h;
      const double fd = (tet_energy(GetParam(), lame, plus, Dm_inv, volume) -
                         tet_energy(GetParam(), lame, minus, Dm_inv, volume)) /
                        (2 * h);
      EXPECT_NEAR(g[i], fd, 1e-6 * (1.0 + g.norm()));
      const Vector12d dg = (tet_gradient(GetParam(), lame, plus, Dm_inv, volume) -
                            tet_gradient(GetParam(), lame, minus, Dm_inv, volume)) /
                           (2 * h);
      EXPECT_LT((H.col(i) - dg).norm(), 1e-6 * (1.0 + H.norm()));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, MaterialDerivatives, ::testing::ValuesIn(kAllModels),
                         [](const auto& info) { return to_string(info.param); });

}  // namespace
}  // namespace strata
