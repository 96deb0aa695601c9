#pragma once
/// \file meshing_options.hpp
/// Parameters of CGAL Mesh_3 tetrahedralisation (README.md, "Meshing", documents the scene keys).
#include <cstdint>

namespace strata {

/// Mesh_3 criteria and optimisation settings. Lengths in the input's units [m].
struct MeshingOptions {
  /// Upper bound on a tet's circumradius [m] (CGAL cell_size); must be > 0.
  double cell_size = 0.0;
  /// Upper bound on a surface facet's circumradius [m]; 0 → cell_size.
  double facet_size = 0.0;
  /// Upper bound on the distance between a facet's circumcentre and the input surface [m];
  /// 0 → cell_size / 10.
  double facet_distance = 0.0;
  /// Lower bound on the facets' angles [degrees], at most 30 for guaranteed termination.
  double facet_angle = 25.0;
  /// Upper bound on a tet's circumradius / shortest edge (≥ 2 for guaranteed termination).
  double cell_radius_edge_ratio = 3.0;
  /// Preserve sharp edges of a polyhedral surface (dihedral angle below feature_angle).
  bool sharp_features = false;
  double feature_angle = 60.0;  ///< [degrees], used with sharp_features
  bool odt = false;             ///< ODT smoothing after refinement
  bool lloyd = false;           ///< Lloyd smoothing after refinement
  bool perturb = true;          ///< sliver perturbation
  bool exude = true;            ///< sliver exudation
  double sliver_bound = 12.0;   ///< [degrees] dihedral-angle target of perturb and exude
  std::uint32_t seed = 0;       ///< seed of CGAL's default random generator
  /// Refuse a request whose estimated tet count exceeds this (memory guard, ≈ 1 kB per tet).
  double max_tets = 5.0e6;
};

}  // namespace strata
