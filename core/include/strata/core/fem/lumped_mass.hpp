#pragma once
/// \file lumped_mass.hpp
/// Lumped (diagonal) mass: each tet gives a quarter of ρ·V to each of its vertices.
#include "strata/core/common/types.hpp"

namespace strata {

/// Per-vertex lumped mass [kg], #V entries; sums to ρ · total volume.
VectorXd lumped_vertex_mass(ConstRef<VectorXd> rest_volume, ConstRef<MatrixX4i> tets,
                            Index num_vertices, double density);

/// The same masses per DOF: each vertex's mass on its three coordinates, 3·#V entries.
VectorXd per_dof_mass(ConstRef<VectorXd> vertex_mass);

}  // namespace strata
