#pragma once
/// \file static_solver.hpp
/// Quasi-static equilibrium at a load factor λ ∈ (0, 1]: minimises the total potential energy
///   Π(x) = Ψ(x) − λ f_extᵀx + Φ_ground(x)
/// over the free DOFs, with the Dirichlet groups at ramp factor s = λ, by Newton with line search
/// and PSD-projected element Hessians (newton_solver.hpp). Convergence: ‖∇Π‖ over the free DOFs ≤
/// tolerance × max(‖λ f_ext‖, ‖f_int(x₀)‖) — the applied load, or for purely prescribed motion
/// the internal forces of the initial guess x₀.
#include <optional>

#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"

namespace strata {

class StaticSolver {
 public:
  /// All references must outlive this object. `ground_stiffness` [N/m] is used when `ground`
  /// is set.
  StaticSolver(const EmbeddedElasticModel& model, const VectorXd& external_forces,
               const std::vector<DirichletGroup>& groups, const std::vector<char>& constrained,
               const std::optional<GroundPlane>& ground, double ground_stiffness,
               LinearSolverKind solver, int max_newton_iterations, double newton_tolerance);

  /// Equilibrium at load factor λ starting from the initial guess `x` (3·#V; its Dirichlet DOFs
  /// are overwritten with the targets at s = λ). `x` is updated in place.
  NewtonResult solve(double load_factor, VectorXd& x);

  /// Total potential Π(x) at load factor λ.
  double potential(double load_factor, const VectorXd& x) const;
  /// Ground penalty forces −∂Φ/∂x at x (zero vector without ground).
  VectorXd contact_forces(const VectorXd& x) const;

  const SpdSolver& linear_solver() const { return m_solver; }

 private:
  const EmbeddedElasticModel& m_model;
  const VectorXd& m_external_forces;
  const std::vector<DirichletGroup>& m_groups;
  const std::optional<GroundPlane>& m_ground;
  double m_ground_stiffness;
  SpdSolver m_solver;
  DofReduction m_reduction;
  int m_max_iterations;
  double m_tolerance;
};

}  // namespace strata
