#pragma once
/// \file implicit_euler.hpp
/// Backward Euler as minimisation of the incremental potential (Martin et al. 2011, "Example-based
/// elastic materials"; Gast et al. 2015), a sum of energy terms:
///   E(q) = 1/(2h²) ‖q − q̃‖²_M + Ψ(q) − f_extᵀq + 1/(2h) (q − qₙ)ᵀ (α M + β Kₙ) (q − qₙ),
///   q̃ = qₙ + h vₙ,  v_{n+1} = (q_{n+1} − qₙ)/h
/// (inertia, elastic, external work, Rayleigh damping), whose stationarity condition is
/// M (v_{n+1} − vₙ)/h = f_int(q_{n+1}) + f_ext − (α M + β Kₙ) v_{n+1}: Rayleigh damping with the
/// stiffness Kₙ lagged to the start of the step (PSD-projected, so E stays convex in the damping
/// term). Minimised by Newton (newton_solver.hpp) from the warm start q̃, with the Dirichlet DOFs,
/// set to their targets at t + h, eliminated. Unconditionally stable for the linear problem.
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/energy/inertia_term.hpp"
#include "strata/core/sim/energy/rayleigh_damping_term.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/problem.hpp"
#include "strata/core/sim/static_solver.hpp"

namespace strata {

class ImplicitEuler {
 public:
  /// `problem` must outlive this object.
  ImplicitEuler(const Problem& problem, LinearSolverKind solver, NewtonControls controls);

  /// One step from t to t + h, updating q and v (3·#Q). Returns Newton's result; the caller
  /// decides what a non-converged step means (Simulation throws DivergenceError).
  NewtonResult step(double t, double h, VectorXd& q, VectorXd& v);

  const EnergySum& energy() const { return m_energy; }
  const SpdSolver& linear_solver() const { return m_solver; }
  SpdSolver& linear_solver() { return m_solver; }

 private:
  const Problem& m_problem;
  SpdSolver m_solver;
  DofReduction m_reduction;
  NewtonControls m_controls;
  EnergySum m_energy;
  NewtonWorkspace m_workspace;  ///< the Hessians, kept from step to step
  ExternalWorkTerm* m_external = nullptr;
  VectorXd m_timed_external;  ///< f_ext(t + h) when loads follow amplitudes
  InertiaTerm* m_inertia = nullptr;
  ContactTerm* m_contact = nullptr;
  RayleighDampingTerm* m_damping = nullptr;
};

}  // namespace strata
