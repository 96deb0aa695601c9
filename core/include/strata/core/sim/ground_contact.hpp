#pragma once
/// \file ground_contact.hpp
/// A rigid ground half-space {x : n̂·(x − p) ≥ 0} with Coulomb friction.
///
/// Dynamics (every integrator, after each step): a vertex below the plane is projected onto it,
/// its inward normal velocity is removed (Δv_n = −min(v_n, 0), perfectly inelastic) and its
/// tangential speed is reduced by μ·|Δv_n|, clamped at zero (Coulomb's law applied to the
/// contact impulse).
///
/// Statics: a frictionless penalty potential Φ(x) = ½ k Σ_i max(0, −n̂·(x_i − p))², with
/// k = `ground_penalty_stiffness`. Friction is ignored in static mode (only the normal reaction
/// is modelled), so a static body on the ground needs Dirichlet groups against tangential rigid
/// motion.
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct GroundPlane {
  Vector3d point = Vector3d::Zero();
  Vector3d normal = Vector3d::UnitZ();  ///< points out of the ground, into the free space
  double friction = 0.0;                ///< Coulomb coefficient μ ≥ 0
};

/// Throws InputError naming `where` for non-finite values, a zero normal or μ < 0.
void validate_ground(const GroundPlane& ground, const std::string& where);

/// Projects penetrating vertices and applies the inelastic, frictional velocity update described
/// above to `x` and `v` (3·#V). Vertices with `skip[3·i] != 0` (Dirichlet) are left alone; `skip`
/// may be empty. Returns the number of vertices in contact.
Index project_ground_contact(const GroundPlane& ground, VectorXd& x, VectorXd& v,
                             const std::vector<char>& skip);

/// The inelastic, frictional velocity update of a contact with unit normal n̂ on the velocity
/// relative to the obstacle: the inward normal part is removed (Δv_n = −min(v_n, 0)) and the
/// tangential speed reduced by μ |Δv_n|, clamped at zero.
Vector3d contact_velocity_update(const Vector3d& relative_velocity, const Vector3d& normal,
                                 double friction);

/// Penalty stiffness k [N/m] = factor · E · h, with E Young's modulus [Pa] and h the mean edge
/// length of the rest mesh [m] (a vertex pushed into the ground feels a stiffness comparable to
/// `factor` times that of an element around it).
double ground_penalty_stiffness(double youngs_modulus, double mean_edge_length,
                                double factor = 100.0);

/// Penalty energy Φ(x) [J] for positions x (3·#V).
double ground_penalty_energy(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x);

/// Adds ∂Φ/∂x (3·#V) into `gradient`.
void add_ground_penalty_gradient(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x,
                                 VectorXd& gradient);

/// Adds ∂²Φ/∂x² (the 3×3 block k n̂n̂ᵀ on the diagonal of each penetrating vertex) into `H`,
/// whose pattern must contain every vertex's diagonal 3×3 block.
void add_ground_penalty_hessian(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x,
                                SparseMatrixd& H);

}  // namespace strata
