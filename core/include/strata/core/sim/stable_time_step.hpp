#pragma once
/// \file stable_time_step.hpp
/// CFL-type estimate of the largest stable step of explicit integrators: the time a P-wave needs
/// to cross the thinnest element, dt ≈ min_t h_t / c_p, with h_t = 3 V_t / (largest face area of
/// t) the tet's smallest altitude and c_p = √((λ + 2μ)/ρ). It is an estimate: strata reports it
/// and never changes dt on its own.
#include "strata/core/common/types.hpp"

namespace strata {

/// Smallest altitude over the tets [m]: min_t 3 V_t / max face area. `positions` #V × 3, `tets`
/// #T × 4.
double min_tet_altitude(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets);

/// min_tet_altitude / p_wave_speed [s].
double stable_time_step_estimate(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 double p_wave_speed);

/// Mean edge length over the tets' six edges [m] (edges shared by tets counted per tet).
double mean_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets);

}  // namespace strata
