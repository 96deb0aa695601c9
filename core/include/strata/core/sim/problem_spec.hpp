#pragma once
/// \file problem_spec.hpp
/// What a scene asks of a body before it is bound to a mesh: the material, the Dirichlet groups,
/// the loads, gravity, a ground plane and rigid obstacles. A Simulation binds it to its mesh as a
/// Problem (problem.hpp); an adaptive run binds it to each cut, with the loads mapped from the
/// finest level. Built with designated initialisers; groups, loads, ground and obstacles left out
/// are none, gravity left out is zero:
///   Simulation sim(mesh, {.material = rubber, .dirichlet = {clamp}, .gravity = {0, 0, -9.81}},
///                  settings);
#include <optional>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/obstacle.hpp"

namespace strata {

struct ProblemSpec {
  Material material{};
  std::vector<DirichletSpec> dirichlet{};  ///< fixed and prescribed groups
  std::vector<RegionLoad> loads{};         ///< total forces on regions
  Vector3d gravity = Vector3d::Zero();     ///< [m/s²]
  std::optional<GroundPlane> ground{};     ///< a rigid ground plane
  /// Rigid obstacles (energy/contact_term.hpp): the boundary vertices (unless
  /// SimulationOptions::boundary_contact_points is false) and a driver's further contact points
  /// (SimulationOptions::contact_points) contact them through a barrier in implicit and static
  /// steps, the DOF vertices through a projection in explicit steps.
  std::vector<Obstacle> obstacles{};
};

}  // namespace strata
