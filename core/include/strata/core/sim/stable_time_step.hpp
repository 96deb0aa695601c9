#pragma once
/// \file stable_time_step.hpp
/// Stability limit of the explicit integrators, from the elements and the material's wave speed.
///
/// For the lumped-mass system linearised at rest, the highest angular frequency obeys the element
/// bound ω_max² ≤ max_t ω_t², and for a linear tet with shape-function gradients G = [∇N_0 … ∇N_3]
/// (3 × 4) ω_t² ≤ 4 (3λ + 2μ) λ_max(G Gᵀ) / ρ: the strain energy density is at most
/// ½(3λ + 2μ)‖∇u‖², ‖∇u‖² ≤ λ_max(G Gᵀ) ‖u‖², and each vertex carries ρV/4 of the tet's mass.
/// A step is then stable for symplectic Euler when ω_max dt ≤ 2 and for RK4 when ω_max dt ≤ 2√2
/// (its stability interval on the imaginary axis). The bound is a guarantee for the linearised
/// problem, not a sharp value: on box meshes the true limit is about 1.5× larger. Stiffening under
/// large deformation can lower the true limit. strata reports it and never changes dt on its own.
///
/// The element bound holds for any partition of the tets into groups, each assembled on its own
/// with its own lumped masses: K = Σ_g K_g and M = Σ_g M_g, so uᵀKu / uᵀMu ≤ max_g ω_g², where
/// ω_g² is the largest eigenvalue of M_g⁻¹ K_g (Irons & Treharne 1971; Hughes, *The Finite
/// Element Method*, §9.1). Groups of neighbouring tets give a tighter bound than single tets: on
/// the eight children of a red-refined Kuhn tet the group's limit is 1.48× the element formula's
/// (ν = 0.3), the dense 3n × 3n eigenvalue problem of the group being solved exactly.
#include <span>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/sim/solver_settings.hpp"

namespace strata {

/// Upper bound on ω_max [rad/s] (see above). `positions` #V × 3, `tets` #T × 4.
double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material);

/// Upper bound on ω_max [rad/s] over a partition of the tets into groups: `groups[t]` is tet t's
/// group (any id ≥ 0; tets with the same id form a group of at most kMaxStabilityGroupTets), or −1
/// for a tet on its own, which takes the closed-form element bound above. A group's K_g is the
/// linear isotropic stiffness at rest (λ, μ of the material, the same for every model there) and
/// M_g the lumped masses ρV/4 of its tets. `groups` empty: every tet on its own (the function
/// above). std::invalid_argument for a size other than #T or a group above the limit.
double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material, std::span<const int> groups);

/// The largest group max_angular_frequency_bound accepts (its eigenproblem is dense).
inline constexpr int kMaxStabilityGroupTets = 32;

/// ω_max dt bound of a stable step: 2 (symplectic Euler and, as the reference explicit limit,
/// backward Euler), 2√2 (RK4, its stability interval on the imaginary axis).
double explicit_stability_interval(Integrator integrator);

/// Largest step [s] for which `integrator` is stable on the linearised problem at rest:
/// 2/ω (symplectic Euler), 2√2/ω (RK4). Backward Euler is unconditionally stable; for it the
/// symplectic Euler value is returned as the reference explicit limit.
double stable_time_step_estimate(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 const Material& material, Integrator integrator,
                                 std::span<const int> groups = {});

/// Mean edge length over the tets' six edges [m] (edges shared by tets counted per tet).
double mean_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets);

/// Mean edge length over the triangles' three edges [m] (edges shared by triangles counted per
/// triangle); 0 without triangles.
double mean_triangle_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX3i> triangles);

}  // namespace strata
