#pragma once
/// \file static_solver.hpp
/// Quasi-static equilibrium at a load factor λ ∈ (0, 1]: minimises the total potential energy
///   Π(q) = Ψ(q) − λ f_extᵀq + Φ_ground(q)
/// (energy terms: elastic, external work, ground penalty) over the free DOFs, with the Dirichlet
/// groups at ramp factor s = λ, by Newton with line search (newton_solver.hpp). Residual
/// criterion: ‖∇Π‖ over the free DOFs ≤ tolerance × max(‖λ f_ext‖, ‖f_int(q₀)‖) — the applied
/// load, or for purely prescribed motion the internal forces of the initial guess q₀.
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/energy/contact_term.hpp"
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/problem.hpp"
#include "strata/core/sim/solver_settings.hpp"

namespace strata {

class StaticSolver {
 public:
  /// `problem` (and what it references) must outlive this object.
  StaticSolver(const Problem& problem, LinearSolverKind solver, NewtonControls controls);

  /// Equilibrium at load factor λ starting from the initial guess `q` (3·#Q; its Dirichlet DOFs
  /// are overwritten with the targets at s = λ). `q` is updated in place.
  NewtonResult solve(double load_factor, VectorXd& q);

  /// Contact: the state friction is measured from (the previous load step's); by default the
  /// initial guess of each solve.
  void set_contact_reference(const VectorXd& q) { m_contact_reference = q; }

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
  ContactTerm* m_contact = nullptr;
  VectorXd m_contact_reference;
  VectorXd m_timed_external;  ///< f_ext(λ) when loads follow amplitudes
};

}  // namespace strata
