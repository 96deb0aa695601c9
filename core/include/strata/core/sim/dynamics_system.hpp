#pragma once
/// \file dynamics_system.hpp
/// The equations of motion shared by the integrators:
///   M a = f_int(x) + f_ext + f_damp(x, v),   f_damp = −(α M + β K(x)) v  (Rayleigh),
/// on the DOFs q of an EmbeddedElasticModel (q = x for a plain mesh), with lumped (diagonal) M,
/// dead loads f_ext and Dirichlet groups ramped by s(t) = min(t/T_r, 1).
///
/// Explicit integrators evaluate K(x) v matrix-free by a one-sided finite difference of the
/// elastic forces, K v ≈ −(f_int(x + εv) − f_int(x)) / ε with ε‖v‖∞ = 10⁻⁷ × the bounding-box
/// diagonal (one extra force evaluation, only when β > 0).
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/embedded_model.hpp"

namespace strata {

struct DynamicsSystem {
  const EmbeddedElasticModel& model;  ///< elastic forces on the DOFs q (x = P q)
  const VectorXd& dof_mass;           ///< lumped mass per DOF, 3·#Q [kg]
  const VectorXd& external_forces;    ///< f_ext, 3·#Q [N]
  double mass_damping;                ///< α [1/s]
  double stiffness_damping;           ///< β [s]
  const std::vector<DirichletGroup>& groups;
  const std::vector<char>& constrained;  ///< 3·#Q flags
  double ramp_time;                      ///< T_r [s] > 0
  double diagonal;                       ///< bounding-box diagonal [m] (FD step scale)

  /// s(t) = min(t / T_r, 1).
  double ramp(double t) const;
  /// ds/dt: 1/T_r while ramping, 0 after.
  double ramp_rate(double t) const;
  /// Writes the Dirichlet targets at time t into x and v.
  void apply_constraints(double t, VectorXd& x, VectorXd& v) const;
  /// Adds −(α M + β K(x)) v into `f`, K v by finite difference; `f_int` = f_int(x).
  void add_damping_forces(const VectorXd& x, const VectorXd& v, const VectorXd& f_int,
                          VectorXd& f) const;
  /// a = M⁻¹ (f_int + f_ext + f_damp); at Dirichlet DOFs the prescribed acceleration at time t.
  void accelerations(double t, const VectorXd& x, const VectorXd& v, VectorXd& a) const;
};

}  // namespace strata
