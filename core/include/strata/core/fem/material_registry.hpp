#pragma once
/// \file material_registry.hpp
/// The constitutive models strata knows, one traits entry per model. The entries drive the scene
/// file's names, the per-element dispatch of the mesh-level loops (elastic_model.cpp instantiates
/// one kernel per entry) and the tests, which run over every entry.
///
/// Adding a model: its energy density, first Piola stress, ∂²ψ/∂F² and singular-frame Hessian in
/// its own header and source (as stvk.hpp, corotated.hpp, neohookean.hpp), one enumerator of
/// MaterialModel, and one model type in core/src/fem/material_models.hpp listed in its
/// MaterialModels (in the enumerators' order, checked when the registry is built).
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/isotropic_hessian.hpp"
#include "strata/core/fem/material.hpp"

namespace strata {

/// Everything strata needs of one constitutive model.
struct MaterialModelTraits {
  MaterialModel model;
  std::string name;     ///< scene-file name (`material.model`)
  std::string summary;  ///< one line: the energy density and where the model fails
  /// Whether ψ stays meaningful for inverted elements (J ≤ 0); if not, runs check det F.
  bool handles_inversion;
  double (*energy_density)(const Matrix3d& F, const LameParameters& lame);  ///< ψ(F)
  Matrix3d (*first_piola)(const Matrix3d& F, const LameParameters& lame);   ///< ∂ψ/∂F
  Matrix9d (*hessian)(const Matrix3d& F, const LameParameters& lame);       ///< ∂²ψ/∂F²
  /// ∂²Ψ̂/∂σ² and the pair eigenvalues at the singular values `sigma` (isotropic_hessian.hpp).
  void (*singular_frame)(const Vector3d& sigma, const LameParameters& lame,
                         SingularFrameHessian& hessian);
};

/// Every model, in MaterialModel's order.
const std::vector<MaterialModelTraits>& material_registry();

/// The entry of `model`.
const MaterialModelTraits& material_traits(MaterialModel model);

/// The entry named `name`; throws InputError listing the registered names.
const MaterialModelTraits& material_traits(const std::string& name);

/// The registered names, in registry order.
std::vector<std::string> material_model_names();

}  // namespace strata
