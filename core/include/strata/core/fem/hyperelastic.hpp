#pragma once
/// \file hyperelastic.hpp
/// Model dispatch for the energy density ψ(F), P = ∂ψ/∂F and ∂²ψ/∂F². A switch per call, so
/// mesh-level loops hoist it out of the element loop (see elastic_model.cpp).
#include "strata/core/fem/corotated.hpp"
#include "strata/core/fem/neohookean.hpp"
#include "strata/core/fem/stvk.hpp"

namespace strata {

double psi(MaterialModel model, const Matrix3d& F, const LameParameters& lame);
Matrix3d dpsi_dF(MaterialModel model, const Matrix3d& F, const LameParameters& lame);
Matrix9d d2psi_dF2(MaterialModel model, const Matrix3d& F, const LameParameters& lame);

}  // namespace strata
