#pragma once
/// \file problem.hpp
/// What a scene means, bound to one mesh or active cut: the elastic model on the DOFs q (x = P q,
/// embedded_model.hpp), lumped masses, dead loads, Rayleigh damping, Dirichlet groups and the
/// ground. Steppers read it; the energy terms of a Newton step are built from it
/// (`add_static_terms`, `add_implicit_euler_terms`).
///
/// Equations of motion (explicit integrators):
///   M a = f_int(x) + f_ext + f_damp(x, v),   f_damp = −(α M + β K(x)) v  (Rayleigh),
/// with lumped (diagonal) M and Dirichlet groups ramped by s(t) = min(t/T_r, 1). K(x) v is
/// evaluated matrix-free by a one-sided finite difference of the elastic forces,
/// K v ≈ −(f_int(x + εv) − f_int(x)) / ε with ε‖v‖∞ = 10⁻⁷ × the bounding-box diagonal (one extra
/// force evaluation, only when β > 0).
///
/// Built with designated initialisers; the referenced data must outlive the Problem:
///   Problem problem{.model = m, .dof_mass = M, .external_forces = f, .groups = g,
///                   .constrained = c, .ramp_time = T, .diagonal = d};
#include <memory>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/energy/contact_term.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/multigrid.hpp"
#include "strata/core/sim/surface_springs.hpp"

namespace strata {

class SpdSolver;

class EnergySum;

struct Problem {
  const EmbeddedElasticModel& model;  ///< elastic forces on the DOFs q (x = P q)
  const VectorXd& dof_mass;           ///< lumped mass per DOF, 3·#Q [kg]
  /// f_ext of the loads without an amplitude at full load, 3·#Q [N]: constant in dynamic runs,
  /// scaled by the load factor in static ones.
  const VectorXd& external_forces;
  const std::vector<DirichletGroup>& groups;
  const std::vector<char>& constrained;  ///< 3·#Q flags
  double mass_damping = 0.0;             ///< α [1/s]
  double stiffness_damping = 0.0;        ///< β [s]
  double ramp_time = 1.0;                ///< T_r [s] > 0 (dynamic ramp of prescribed motion)
  double diagonal = 1.0;                 ///< bounding-box diagonal [m] (FD step scale)
  const GroundPlane* ground = nullptr;   ///< optional rigid ground
  double ground_stiffness = 0.0;         ///< penalty k [N/m] of the static ground term
  /// Optional coarser spaces below the DOF vertices (the refinement tree's levels) for the
  /// multigrid linear solver; null: none.
  const NestedSpaces* nested_spaces = nullptr;
  /// Smoother estimates from a hierarchy on a nearby system for the first multigrid setup on
  /// nested_spaces (MultigridPreconditioner::seed_smoother_estimates); null or empty: none.
  const std::vector<SmootherEstimate>* smoother_estimates = nullptr;
  /// Coarse levels of a hierarchy on a nearby system offered to that first setup
  /// (SpdSolver::use_nested_spaces); null or empty: none.
  const std::shared_ptr<MultigridCoarseLevels>* coarse_levels = nullptr;
  /// Loads that follow their own amplitude s_k(t) (3·#Q each); null or empty: none.
  const std::vector<TimedForces>* timed_forces = nullptr;
  /// Surface springs on the DOF vertices (meshes without an embedding); null: none.
  const SurfaceSprings* springs = nullptr;
  /// Rigid obstacles (energy/contact_term.hpp), the points tested against them and the
  /// contact settings; null or empty: none.
  const std::vector<Obstacle>* obstacles = nullptr;
  const std::vector<ContactPoint>* contact_points = nullptr;
  ContactSettings contact{};

  /// s(t) = min(t / T_r, 1).
  double ramp(double t) const;
  /// ds/dt: 1/T_r while ramping, 0 after.
  double ramp_rate(double t) const;
  /// Whether there are obstacles to contact.
  bool has_obstacles() const { return obstacles != nullptr && !obstacles->empty(); }
  /// Whether any load follows its own amplitude.
  bool has_timed_forces() const { return timed_forces != nullptr && !timed_forces->empty(); }
  /// f = base_scale · external_forces + Σ_k s_k(t) f_k (3·#Q): the external forces at time t
  /// (base_scale 1) or at load factor λ = t (base_scale λ).
  void external_forces_at(double t, double base_scale, VectorXd& f) const;
  /// Writes the Dirichlet targets at time t into x and v.
  void apply_constraints(double t, VectorXd& x, VectorXd& v) const;
  /// Adds −(α M + β K(x)) v into `f`, K v by finite difference; `f_int` = f_int(x).
  void add_damping_forces(const VectorXd& x, const VectorXd& v, const VectorXd& f_int,
                          VectorXd& f) const;
  /// f_int = elastic forces (+ surface spring forces), 3·#Q.
  void internal_forces(const VectorXd& x, VectorXd& f_int) const;
  /// internal_forces and, from the same pass over the tets, the smallest volume ratio det F and its
  /// tet (ElasticModel::min_volume_ratio); needs model.is_identity().
  std::pair<double, Index> internal_forces_and_min_volume_ratio(const VectorXd& x,
                                                                VectorXd& f_int) const;
  /// a = M⁻¹ (f_int + f_ext + f_damp); at Dirichlet DOFs the prescribed acceleration at time t.
  void accelerations(double t, const VectorXd& x, const VectorXd& v, VectorXd& a) const;
  /// solver.use_nested_spaces with nested_spaces, the free DOFs of the implicit stepper's
  /// reduction, and the smoother estimates and coarse levels offered to its first setup.
  void use_nested_spaces(SpdSolver& solver, const std::vector<Index>& free_dofs) const;
};

}  // namespace strata
