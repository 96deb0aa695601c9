#pragma once
/// \file material.hpp
/// Isotropic hyperelastic material: model choice and parameters.
#include <optional>
#include <string>

#include "strata/core/fem/plasticity.hpp"

namespace strata {

/// Constitutive models. All are isotropic and take Young's modulus and Poisson's ratio.
/// - stvk: St. Venant–Kirchhoff, ψ = μ‖E‖² + λ/2 tr(E)², E = ½(FᵀF − I). Loses stability under
///   strong compression and cannot handle inverted elements.
/// - corotated: corotated linear, ψ = μ‖F − R‖² + λ/2 tr(RᵀF − I)², F = RS (polar decomposition).
/// - neohookean: stable neo-Hookean (Smith, de Goes, Kim 2018),
///   ψ = μ'/2 (I_C − 3) + λ'/2 (J − α)² − μ'/2 log(I_C + 1), α = 1 + 3μ'/(4λ'), with
///   μ' = 4μ/3 and λ' = λ + 5μ/6 so that it linearises to the same Lamé parameters.
enum class MaterialModel { stvk, corotated, neohookean };

/// Scene-file name of a model ("stvk", "corotated", "neohookean").
std::string to_string(MaterialModel model);

/// Parses a scene-file model name; throws InputError listing the valid names.
MaterialModel material_model_from_string(const std::string& name);

/// Whether the model stays meaningful for inverted elements (J ≤ 0).
bool handles_inversion(MaterialModel model);

/// Lamé parameters from Young's modulus E [Pa] and Poisson's ratio ν ∈ [0, ½).
struct LameParameters {
  double mu;      ///< shear modulus μ = E / (2(1+ν)) [Pa]
  double lambda;  ///< λ = Eν / ((1+ν)(1−2ν)) [Pa]
};
LameParameters lame_parameters(double youngs_modulus, double poisson_ratio);

/// A material: model, elastic constants, density, Rayleigh damping and optional plasticity.
struct Material {
  MaterialModel model = MaterialModel::stvk;
  double youngs_modulus = 1e6;     ///< E [Pa]
  double poisson_ratio = 0.3;      ///< ν, dimensionless, in [0, 0.5)
  double density = 1000.0;         ///< ρ [kg/m³]
  double mass_damping = 0.0;       ///< Rayleigh α [1/s]: damping force −α M v
  double stiffness_damping = 0.0;  ///< Rayleigh β [s]: damping force −β K v
  /// von Mises plasticity (plasticity.hpp); none: purely elastic.
  std::optional<Plasticity> plasticity;

  LameParameters lame() const { return lame_parameters(youngs_modulus, poisson_ratio); }
  /// P-wave speed √((λ + 2μ)/ρ) [m/s], the fastest elastic wave.
  double p_wave_speed() const;
};

/// Throws InputError (naming `where`, e.g. "material") unless E > 0, 0 ≤ ν < 0.5, ρ > 0, the
/// damping coefficients are ≥ 0 and the plasticity (if any) is valid.
void validate_material(const Material& material, const std::string& where);

}  // namespace strata
