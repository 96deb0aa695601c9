#pragma once
/// \file implicit_euler.hpp
/// Backward Euler as minimisation of the incremental potential (Martin et al. 2011, "Example-based
/// elastic materials"; Gast et al. 2015):
///   E(x) = 1/(2h²) ‖x − x̃‖²_M + Ψ(x) − f_extᵀx + 1/(2h) (x − xₙ)ᵀ (α M + β Kₙ) (x − xₙ),
///   x̃ = xₙ + h vₙ,  v_{n+1} = (x_{n+1} − xₙ)/h,
/// whose stationarity condition is M (v_{n+1} − vₙ)/h = f_int(x_{n+1}) + f_ext − (α M + β Kₙ)
/// v_{n+1}: Rayleigh damping with the stiffness Kₙ lagged to the start of the step (PSD-projected,
/// so E stays convex in the damping term). Minimised by Newton (newton_solver.hpp) with
/// PSD-projected element Hessians and the Dirichlet DOFs, set to their targets at t + h,
/// eliminated. Unconditionally stable for the linear problem.
#include <memory>

#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/dynamics_system.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"

namespace strata {

class ImplicitEuler {
 public:
  /// `system` must outlive this object.
  ImplicitEuler(const DynamicsSystem& system, LinearSolverKind solver, int max_newton_iterations,
                double newton_tolerance);

  /// One step from t to t + h, updating x and v (3·#V). Returns Newton's result; the caller
  /// decides what a non-converged step means (Simulation throws DivergenceError).
  NewtonResult step(double t, double h, VectorXd& x, VectorXd& v);

  const SpdSolver& linear_solver() const { return m_solver; }

 private:
  const DynamicsSystem& m_system;
  SpdSolver m_solver;
  DofReduction m_reduction;
  int m_max_iterations;
  double m_tolerance;
  SparseMatrixd m_damping_stiffness;  ///< Kₙ (projected), same pattern as the model's stiffness
};

}  // namespace strata
