#include "strata/core/fem/material_registry.hpp"

#include <stdexcept>

#include "material_models.hpp"
#include "strata/core/common/error.hpp"

namespace strata {

namespace {

template <typename Model>
MaterialModelTraits traits_of() {
  return {Model::model,          Model::name,        Model::summary, Model::handles_inversion,
          Model::energy_density, Model::first_piola, Model::hessian, Model::singular_frame};
}

template <typename... Models>
std::vector<MaterialModelTraits> build_registry(detail::ModelList<Models...>) {
  std::vector<MaterialModelTraits> registry = {traits_of<Models>()...};
  for (std::size_t i = 0; i < registry.size(); ++i)
    if (static_cast<std::size_t>(registry[i].model) != i)
      throw std::logic_error("material registry: entry " + registry[i].name +
                             " is out of MaterialModel's order");
  return registry;
}

}  // namespace

const std::vector<MaterialModelTraits>& material_registry() {
  static const std::vector<MaterialModelTraits> registry = build_registry(detail::MaterialModels{});
  return registry;
}

const MaterialModelTraits& material_traits(MaterialModel model) {
  const auto& registry = material_registry();
  const auto index = static_cast<std::size_t>(model);
  if (index >= registry.size())
    throw std::logic_error("material model " + std::to_string(index) + " is not registered");
  return registry[index];
}

std::vector<std::string> material_model_names() {
  std::vector<std::string> names;
  for (const MaterialModelTraits& traits : material_registry())
    names.push_back(traits.name);
  return names;
}

const MaterialModelTraits& material_traits(const std::string& name) {
  std::string expected;
  for (const MaterialModelTraits& traits : material_registry()) {
    if (traits.name == name) return traits;
    expected += (expected.empty() ? "" : ", ") + traits.name;
  }
  throw InputError("unknown material model \"" + name + "\" (expected " + expected + ")");
}

}  // namespace strata
