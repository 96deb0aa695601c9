// The material registry: every entry is reachable by its scene-file name and by its enumerator,
// an unknown name is refused with the full list, and each entry's flags say what its functions do.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "fem_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/material_registry.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

TEST(MaterialRegistry, NamesAndEnumeratorsRoundTrip) {
  const auto& registry = material_registry();
  ASSERT_FALSE(registry.empty());
  std::set<std::string> names;
  for (std::size_t i = 0; i < registry.size(); ++i) {
    const MaterialModelTraits& traits = registry[i];
    EXPECT_EQ(static_cast<std::size_t>(traits.model), i) << traits.name;
    EXPECT_TRUE(names.insert(traits.name).second) << "duplicate name " << traits.name;
    EXPECT_FALSE(traits.summary.empty()) << traits.name;
    EXPECT_EQ(to_string(traits.model), traits.name);
    EXPECT_EQ(material_model_from_string(traits.name), traits.model);
    EXPECT_EQ(&material_traits(traits.model), &traits);
    EXPECT_EQ(handles_inversion(traits.model), traits.handles_inversion);
  }
  EXPECT_EQ(material_model_names().size(), registry.size());
}

TEST(MaterialRegistry, UnknownNameListsEveryModel) {
  try {
    material_model_from_string("linear");
    FAIL() << "an unknown model name was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("\"linear\""), std::string::npos) << message;
    for (const std::string& name : material_model_names())
      EXPECT_NE(message.find(name), std::string::npos) << message;
  }
}

// The scalar dispatch (hyperelastic.hpp) and the mesh loops (elastic_model.cpp) reach the same
// model: the energy of a one-tet mesh equals V ψ(F) from the entry's own function.
TEST(MaterialRegistry, MeshLoopsDispatchToTheEntry) {
  std::mt19937 rng(5);
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 1.0), {1, 1, 1});
  for (const MaterialModelTraits& traits : material_registry()) {
    Material material;
    material.model = traits.model;
    const ElasticModel model(mesh.vertices, mesh.tets, material);
    const LameParameters lame = material.lame();
    const Matrix3d F = testing::random_deformation_gradient(rng, 0.3);
    VectorXd x(model.num_dofs());
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      x.segment<3>(3 * v) = F * mesh.vertices.row(v).transpose();
    const double expected = 1.0 * traits.energy_density(F, lame);  // unit cube volume
    EXPECT_NEAR(model.energy(x), expected, 1e-12 * std::abs(expected)) << traits.name;
    EXPECT_EQ(psi(traits.model, F, lame), traits.energy_density(F, lame)) << traits.name;
  }
}

// A model that claims to handle inversion has a finite energy and stress for an inverted F.
TEST(MaterialRegistry, InversionFlagMeansFiniteAtInvertedF) {
  const Matrix3d inverted = Vector3d(1.1, 0.9, -0.4).asDiagonal();
  for (const MaterialModelTraits& traits : material_registry()) {
    if (!traits.handles_inversion) continue;
    const LameParameters lame = lame_parameters(1e6, 0.3);
    EXPECT_TRUE(std::isfinite(traits.energy_density(inverted, lame))) << traits.name;
    EXPECT_TRUE(traits.first_piola(inverted, lame).allFinite()) << traits.name;
    // It resists: the stress pushes the third axis back out (P₂₂ < 0 at σ₂ < 0).
    EXPECT_LT(traits.first_piola(inverted, lame)(2, 2), 0.0) << traits.name;
  }
}

}  // namespace
}  // namespace strata
