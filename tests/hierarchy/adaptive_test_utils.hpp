#pragma once
// Shared scene pieces for the tests of the adaptive driver: a rubber-like material, plane
// Dirichlet groups, box loads and hierarchy settings.
#include <string>

#include "strata/core/fem/material.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"

namespace strata::testing {

/// Stable neo-Hookean, E = 1 MPa, ν = 0.3, ρ = 1000 kg/m³.
inline Material rubber() {
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

/// A fixed group on the plane through `point` with `normal` (zero tolerance).
inline DirichletSpec fixed_plane(const std::string& name, const Vector3d& point,
                                 const Vector3d& normal) {
  DirichletSpec spec;
  spec.name = name;
  spec.region = PlaneRegion{point, normal, 0.0};
  return spec;
}

/// A total force on the box [lo, hi], named "forces.0".
inline RegionLoad box_load(const Vector3d& lo, const Vector3d& hi, const Vector3d& force) {
  RegionLoad load;
  load.name = "forces.0";
  load.region = BoxRegion{lo, hi};
  load.total_force = force;
  return load;
}

/// The driver with periodic adaptation (every `adapt_every` steps, no redo, no initial
/// adaptation) and the force indicator: the mechanics these tests check. The error-controlled
/// defaults (recovery indicator, tolerance, in-step refinement) are tested on their own.
inline HierarchySettings hierarchy(int levels, HierarchyMode mode, int level = 0) {
  HierarchySettings settings;
  settings.levels = levels;
  settings.mode = mode;
  settings.level = level;
  settings.indicator = "force";
  settings.in_step_refinement = false;
  settings.initial_adaptation = false;
  return settings;
}

}  // namespace strata::testing
