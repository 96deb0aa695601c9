#pragma once
// The constitutive models as types, one per registry entry (material_registry.hpp). The
// mesh-level loops visit the type of a run's model once and inline its functions in the element
// loop. Optional members: a `LaneKernel` runs forces four tets at a time
// (batched_stress_kernels.hpp); `stiffness_blocks` gives the exact element stiffness of one tet in
// closed form, and a `StiffnessLaneKernel` that of four tets at a time
// (batched_stiffness_kernels.hpp).
#include <stdexcept>
#include <string>

#include "batched_stiffness_kernels.hpp"
#include "batched_stress_kernels.hpp"
#include "strata/core/fem/corotated.hpp"
#include "strata/core/fem/isotropic_hessian.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/fem/neohookean.hpp"
#include "strata/core/fem/stvk.hpp"

namespace strata::detail {

struct StvkModel {
  static constexpr MaterialModel model = MaterialModel::stvk;
  static constexpr const char* name = "stvk";
  static constexpr const char* summary =
      "St. Venant-Kirchhoff, psi = mu |E|^2 + lambda/2 tr(E)^2; softens under strong compression "
      "and is undefined for inverted elements";
  static constexpr bool handles_inversion = false;
  using LaneKernel = StvkLanes;
  using StiffnessLaneKernel = StvkStiffnessLanes;
  static constexpr auto* stiffness_blocks = &stvk_stiffness_blocks;
  static constexpr auto* energy_density = &psi_stvk;
  static constexpr auto* first_piola = &dpsi_stvk_dF;
  static constexpr auto* hessian = &d2psi_stvk_dF2;
  static constexpr auto* singular_frame = &stvk_singular_frame;
};

struct CorotatedModel {
  static constexpr MaterialModel model = MaterialModel::corotated;
  static constexpr const char* name = "corotated";
  static constexpr const char* summary =
      "corotated linear, psi = mu |F - R|^2 + lambda/2 tr(R^T F - I)^2 with F = RS; handles "
      "inversion";
  static constexpr bool handles_inversion = true;
  static constexpr auto* energy_density = &psi_corotated;
  static constexpr auto* first_piola = &dpsi_corotated_dF;
  static constexpr auto* hessian = &d2psi_corotated_dF2;
  static constexpr auto* singular_frame = &corotated_singular_frame;
};

struct NeoHookeanModel {
  static constexpr MaterialModel model = MaterialModel::neohookean;
  static constexpr const char* name = "neohookean";
  static constexpr const char* summary =
      "stable neo-Hookean (Smith, de Goes, Kim 2018), linearising to the same Lame parameters; "
      "handles inversion";
  static constexpr bool handles_inversion = true;
  using LaneKernel = NeoHookeanLanes;
  using StiffnessLaneKernel = NeoHookeanStiffnessLanes;
  static constexpr auto* stiffness_blocks = &neohookean_stiffness_blocks;
  static constexpr auto* energy_density = &psi_neohookean;
  static constexpr auto* first_piola = &dpsi_neohookean_dF;
  static constexpr auto* hessian = &d2psi_neohookean_dF2;
  static constexpr auto* singular_frame = &neohookean_singular_frame;
};

template <typename... Models>
struct ModelList {};

/// Every model, in MaterialModel's order.
using MaterialModels = ModelList<StvkModel, CorotatedModel, NeoHookeanModel>;

template <typename Visitor, typename... Models>
void visit_model_in(MaterialModel model, Visitor&& visitor, ModelList<Models...>) {
  const bool found = ((Models::model == model ? (visitor(Models{}), true) : false) || ...);
  if (!found)
    throw std::logic_error("material model " + std::to_string(static_cast<int>(model)) +
                           " is not registered");
}

/// Calls `visitor(Model{})` with the model type of `model`.
template <typename Visitor>
void visit_material_model(MaterialModel model, Visitor&& visitor) {
  visit_model_in(model, visitor, MaterialModels{});
}

}  // namespace strata::detail
