#pragma once
/// \file plasticity.hpp
/// von Mises plasticity with linear isotropic hardening, multiplicative F = Fₑ Fₚ.
///
/// Every tet carries its plastic deformation Fₚ (through Fₚ⁻¹) and its equivalent plastic strain
/// ε̄ₚ: the elastic energy of a tet is V ψ(Fₑ) with Fₑ = F Fₚ⁻¹ and ψ the elastic model's density
/// (stvk, corotated or neohookean). Plastic flow is isochoric (det Fₚ = 1), so rest volumes and
/// masses never change.
///
/// Return mapping (the exact radial return of the logarithmic-strain model; Simo 1992): with the
/// trial Fₑ = F Fₚ⁻¹ = U diag(σ) Vᵀ, the Hencky strain ε = log σ (principal), its Kirchhoff stress
/// τ = 2μ ε + λ tr(ε), and the equivalent stress q = √(3/2) ‖dev τ‖ = √6 μ ‖dev ε‖, a tet yields
/// where
///   f = q − (σ_y + H ε̄ₚ) > 0.
/// It then flows by Δε̄ = f / (3μ + H) along dev ε:
///   ε ← ε − Δε̄ √(3/2) dev ε / ‖dev ε‖,   ε̄ₚ ← ε̄ₚ + Δε̄,   Fₚ⁻¹ ← Fₚ⁻¹ V diag(e^{Δε}) Vᵀ,
/// which puts the stress back on the yield surface (q = σ_y + H ε̄ₚ). The yield test is in the
/// Hencky measure for all three elastic models: it agrees with each model's own stress to first
/// order in the elastic strain (of order σ_y / E). ε̄ₚ stops at `max_plastic_strain` (the tet is
/// elastic beyond it). Inverted or degenerate trial states (σ_min ≤ 10⁻¹²) do not flow.
///
/// The drivers (simulation.hpp) update the state after each step; implicit steps repeat the step
/// with the updated state until ε̄ₚ changes by less than a tolerance between passes, which is the
/// implicit (backward-Euler) return mapping of the whole step.
#include <limits>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

class ElasticModel;
struct LameParameters;

/// Scene `material.plasticity`.
struct Plasticity {
  double yield_stress = 0.0;  ///< σ_y [Pa] > 0 (von Mises)
  double hardening = 0.0;     ///< H [Pa] ≥ 0, linear isotropic
  /// Cap on the equivalent plastic strain ε̄ₚ (> 0); infinity: none.
  double max_plastic_strain = std::numeric_limits<double>::infinity();
};

/// Throws InputError naming `where` (e.g. "material.plasticity") unless σ_y > 0 and finite,
/// H ≥ 0 and finite, max_plastic_strain > 0.
void validate_plasticity(const Plasticity& plasticity, const std::string& where);

/// Per-tet plastic state.
struct PlasticState {
  std::vector<Matrix3d> plastic_inverse;  ///< Fₚ⁻¹ per tet (#T)
  VectorXd equivalent_strain;             ///< ε̄ₚ per tet (#T)

  /// The virgin state: Fₚ = I, ε̄ₚ = 0.
  static PlasticState identity(Index num_tets);
  Index num_tets() const { return equivalent_strain.size(); }
  bool empty() const { return plastic_inverse.empty(); }
};

/// One tet's return mapping from total F and its state at the start of the step.
struct ElementReturn {
  Matrix3d plastic_inverse;  ///< Fₚ⁻¹ after the step
  double equivalent_strain;  ///< ε̄ₚ after the step
  bool yielded;              ///< whether it flowed
};
ElementReturn return_map(const Matrix3d& F, const Matrix3d& plastic_inverse,
                         double equivalent_strain, const LameParameters& lame,
                         const Plasticity& plasticity);

/// √(3/2) ‖dev τ‖ of the Hencky model at Fₑ [Pa] (0 for an inverted or degenerate Fₑ).
double hencky_equivalent_stress(const Matrix3d& Fe, const LameParameters& lame);

/// The return mapping of every tet of `model` at mesh positions `x` (3·#V) from the state `start`
/// (the state at the start of the step). Parallel. `yielded`, if given, receives the number of
/// tets that flowed.
PlasticState return_map(const ElasticModel& model, ConstRef<VectorXd> x, const PlasticState& start,
                        const Plasticity& plasticity, Index* yielded = nullptr);

}  // namespace strata
