#pragma once
// The constitutive models as types, one per registry entry (material_registry.hpp). The
// mesh-level loops visit the type of a run's model once and inline its functions in the element
// loop. Optional members: a `LaneKernel` runs forces four tets at a time
// (batched_stress_kernels.hpp); a `StiffnessLaneKernel` with `stiffness_blocks` gives the exact
// element stiffness in closed form (batched_stiffness_kernels.hpp), four tets and one at a time.
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
  static void stiffness_blocks(const Matrix3d& F, const Eigen::Matrix<double, 4, 3>& grad_N,
                               const LameParameters& lame, double volume,
                               Matrix3d (&blocks)[4][4]) {
    stvk_stiffness_blocks(F, grad_N, lame, volume, blocks);
  }
  static double energy_density(const Matrix3d& F, const LameParameters& lame) {
    return psi_stvk(F, lame);
  }
  static Matrix3d first_piola(const Matrix3d& F, const LameParameters& lame) {
    return dpsi_stvk_dF(F, lame);
  }
  static Matrix9d hessian(const Matrix3d& F, const LameParameters& lame) {
    return d2psi_stvk_dF2(F, lame);
  }
  static void singular_frame(const Vector3d& sigma, const LameParameters& lame,
                             SingularFrameHessian& h) {
    stvk_singular_frame(sigma, lame, h);
  }
};

struct CorotatedModel {
  static constexpr MaterialModel model = MaterialModel::corotated;
  static constexpr const char* name = "corotated";
  static constexpr const char* summary =
      "corotated linear, psi = mu |F - R|^2 + lambda/2 tr(R^T F - I)^2 with F = RS; handles "
      "inversion";
  static constexpr bool handles_inversion = true;
  static double energy_density(const Matrix3d& F, const LameParameters& lame) {
    return psi_corotated(F, lame);
  }
  static Matrix3d first_piola(const Matrix3d& F, const LameParameters& lame) {
    return dpsi_corotated_dF(F, lame);
  }
  static Matrix9d hessian(const Matrix3d& F, const LameParameters& lame) {
    return d2psi_corotated_dF2(F, lame);
  }
  static void singular_frame(const Vector3d& sigma, const LameParameters& lame,
                             SingularFrameHessian& h) {
    corotated_singular_frame(sigma, lame, h);
  }
};

struct NeoHookeanModel {
  static constexpr MaterialModel model = MaterialModel::neohookean;
  static constexpr const char* name = "neohookean";
  static constexpr const char* summary =
      "stable neo-Hookean (Smith, de Goes, Kim 2018), linearising to the same Lame parameters; "
      "handles inversion";
  static constexpr bool handles_inversion = true;
  using LaneKernel = NeoHookeanLanes;
  static double energy_density(const Matrix3d& F, const LameParameters& lame) {
    return psi_neohookean(F, lame);
  }
  static Matrix3d first_piola(const Matrix3d& F, const LameParameters& lame) {
    return dpsi_neohookean_dF(F, lame);
  }
  static Matrix9d hessian(const Matrix3d& F, const LameParameters& lame) {
    return d2psi_neohookean_dF2(F, lame);
  }
  static void singular_frame(const Vector3d& sigma, const LameParameters& lame,
                             SingularFrameHessian& h) {
    neohookean_singular_frame(sigma, lame, h);
  }
};

template <typename... Models>
struct ModelList {
  static constexpr int size = sizeof...(Models);
};

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
