#include "strata/core/fem/material.hpp"

#include <cmath>

#include "strata/core/common/error.hpp"
#include "strata/core/fem/material_registry.hpp"

namespace strata {

std::string to_string(MaterialModel model) {
  return material_traits(model).name;
}

MaterialModel material_model_from_string(const std::string& name) {
  return material_traits(name).model;
}

bool handles_inversion(MaterialModel model) {
  return material_traits(model).handles_inversion;
}

LameParameters lame_parameters(double youngs_modulus, double poisson_ratio) {
  const double E = youngs_modulus, nu = poisson_ratio;
  return {E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

double Material::p_wave_speed() const {
  const LameParameters l = lame();
  return std::sqrt((l.lambda + 2.0 * l.mu) / density);
}

void validate_material(const Material& material, const std::string& where) {
  if (!(material.youngs_modulus > 0.0) || !std::isfinite(material.youngs_modulus))
    throw InputError(where + ".youngs_modulus: must be positive and finite");
  if (!(material.poisson_ratio >= 0.0 && material.poisson_ratio < 0.5))
    throw InputError(where + ".poisson_ratio: must be in [0, 0.5)");
  if (!(material.density > 0.0) || !std::isfinite(material.density))
    throw InputError(where + ".density: must be positive and finite");
  // Beyond any solid by far; larger values overflow the stiffness and the stable step.
  if (material.youngs_modulus > 1e20)
    throw InputError(where + ".youngs_modulus: must be at most 1e20 Pa");
  if (material.density > 1e10) throw InputError(where + ".density: must be at most 1e10 kg/m^3");
  if (!(material.mass_damping >= 0.0) || !std::isfinite(material.mass_damping))
    throw InputError(where + ".damping.mass: must be >= 0");
  if (!(material.stiffness_damping >= 0.0) || !std::isfinite(material.stiffness_damping))
    throw InputError(where + ".damping.stiffness: must be >= 0");
  if (material.plasticity) validate_plasticity(*material.plasticity, where + ".plasticity");
}

}  // namespace strata
