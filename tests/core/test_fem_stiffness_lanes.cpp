// The mesh stiffness of every registered model, exact and PSD-projected (for StVK the vectorised
// closed form: four tets per lane group, scalar code for the last partial group), against a dense
// assembly of the element Hessians, on meshes whose tet count is not a multiple of the lane width,
// at a large deformation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <tuple>

#include "fem_test_utils.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/tet_element.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

Eigen::MatrixXd dense_element_assembly(const ElasticModel& model, const MatrixX4i& tets,
                                       const VectorXd& x, bool project_psd) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(x.size(), x.size());
  const LameParameters lame = model.material().lame();
  for (Index t = 0; t < tets.rows(); ++t) {
    Vector12d xt;
    for (int k = 0; k < 4; ++k)
      xt.segment<3>(3 * k) = x.segment<3>(3 * tets(t, k));
    const Matrix12d H = tet_hessian(model.material().model, lame, xt, model.rest_data().Dm_inv[t],
                                    model.rest_data().rest_volume[t], project_psd);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        K.block<3, 3>(3 * tets(t, a), 3 * tets(t, b)) += H.block<3, 3>(3 * a, 3 * b);
  }
  return K;
}

class MeshStiffness : public ::testing::TestWithParam<std::tuple<MaterialModel, bool>> {};

TEST_P(MeshStiffness, EqualsDenseAssemblyWithPartialLaneGroups) {
  const auto [kind, project_psd] = GetParam();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  // 162 and 90 tets: both leave a partial lane group after the last full one.
  for (const std::array<int, 3> cells :
       {std::array<int, 3>{3, 3, 3}, std::array<int, 3>{5, 3, 1}}) {
    const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 0.8, 0.6), cells);
    ASSERT_NE(mesh.tets.rows() % 4, 0);
    Material material;
    material.model = kind;
    material.youngs_modulus = 2e5;
    material.poisson_ratio = 0.4;
    const ElasticModel model(mesh.vertices, mesh.tets, material);
    VectorXd x = model.rest_positions();
    for (Index i = 0; i < x.size(); ++i)
      x[i] = 1.3 * x[i] + jitter(rng);  // stretched by 30 % and strongly perturbed
    SparseMatrixd K;
    model.stiffness(x, K, project_psd);
    const Eigen::MatrixXd reference = dense_element_assembly(model, mesh.tets, x, project_psd);
    EXPECT_LT((Eigen::MatrixXd(K) - reference).norm(), 1e-12 * reference.norm());
    // A second call rewrites the values instead of accumulating.
    model.stiffness(x, K, project_psd);
    EXPECT_LT((Eigen::MatrixXd(K) - reference).norm(), 1e-12 * reference.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, MeshStiffness,
                         ::testing::Combine(::testing::ValuesIn(testing::kAllModels),
                                            ::testing::Bool()),
                         [](const auto& info) {
                           return to_string(std::get<0>(info.param)) +
                                  (std::get<1>(info.param) ? "_psd" : "_exact");
                         });

}  // namespace
}  // namespace strata
