#pragma once
/// \file hyperelastic.hpp
/// Model dispatch for the energy density ψ(F), P = ∂ψ/∂F and ∂²ψ/∂F², through the model's
/// registry entry (material_registry.hpp): a registry lookup and an indirect call per evaluation.
/// Mesh-level loops dispatch once per loop instead (elastic_model.cpp).
#include "strata/core/fem/corotated.hpp"
#include "strata/core/fem/neohookean.hpp"
#include "strata/core/fem/stvk.hpp"

namespace strata {

double psi(MaterialModel model, const Matrix3d& F, const LameParameters& lame);
Matrix3d dpsi_dF(MaterialModel model, const Matrix3d& F, const LameParameters& lame);
Matrix9d d2psi_dF2(MaterialModel model, const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
