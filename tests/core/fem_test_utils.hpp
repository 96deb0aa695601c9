#pragma once
// Shared helpers for the FEM tests: random deformation gradients, random rotations, models.
#include <Eigen/Geometry>
#include <array>
#include <random>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/fem/material_registry.hpp"

namespace strata::testing {

/// Every registered model (material_registry.hpp).
inline std::vector<MaterialModel> all_models() {
  std::vector<MaterialModel> models;
  for (const MaterialModelTraits& traits : material_registry())
    models.push_back(traits.model);
  return models;
}
inline const std::vector<MaterialModel> kAllModels = all_models();

inline LameParameters test_lame() {
  return lame_parameters(1.0e6, 0.3);
}

/// F = I + scale · random matrix with entries in [−1, 1] (positive determinant for small scale).
inline Matrix3d random_deformation_gradient(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix3d F;
  for (int i = 0; i < 9; ++i)
    F.data()[i] = uniform(rng);
  return Matrix3d::Identity() + scale * F;
}

inline Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

}  // namespace strata::testing
