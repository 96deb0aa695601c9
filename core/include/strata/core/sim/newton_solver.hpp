#pragma once
/// \file newton_solver.hpp
/// Newton's method with backtracking line search for minimising a potential E(x) over the free
/// DOFs of a 3·#V vector (Dirichlet DOFs keep their values). Used by backward Euler (incremental
/// potential) and static equilibrium (total potential energy).
#include <functional>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/linear_solver.hpp"

namespace strata {

/// The potential to minimise. `hessian` must be symmetric positive semi-definite (project element
/// Hessians) and keep one fixed sparsity pattern: the one the DofReduction was built for.
struct NewtonObjective {
  std::function<double(const VectorXd& x)> energy;                      ///< E(x); +inf if invalid
  std::function<void(const VectorXd& x, VectorXd& gradient)> gradient;  ///< ∂E/∂x, 3·#V
  std::function<void(const VectorXd& x, SparseMatrixd& hessian)> hessian;  ///< ∂²E/∂x², full
};

struct NewtonSettings {
  int max_iterations = 50;
  double tolerance = 1e-10;  ///< stop when ‖g_free‖ ≤ max(tolerance · force_scale, residual_floor)
  double force_scale = 1.0;  ///< [N]
  /// Round-off level of the gradient [N] (see internal_force_roundoff); below it no iteration can
  /// make progress.
  double residual_floor = 0.0;
  /// Magnitude of the terms that make up E [J] (e.g. (2μ + λ)·volume for elastic energy): when
  /// the predicted decrease |gᵀΔ| is below 10⁻¹¹ × max(|E|, energy_scale), E cannot resolve it and
  /// the step is judged by the gradient norm instead.
  double energy_scale = 0.0;
  /// Also stop when the (full) Newton step is at round-off level: ‖Δx‖∞ ≤ step_tolerance [m].
  double step_tolerance = 0.0;
};

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  ///< final ‖g_free‖ [N]
};

/// Round-off level of the elastic forces of `model` near the rest state [N]:
/// 10³ ε_machine · (2μ + λ) · h̄² · √(3·#V), with h̄ the mean rest edge length — the stress noise
/// of F ≈ I times a face area, accumulated over the DOFs.
double internal_force_roundoff(const EmbeddedElasticModel& model);

/// Minimises from the initial guess `x` (3·#V, updated in place). Each iteration: gradient,
/// Hessian, reduce to free DOFs, solve H Δ = −g (on failure, retry with a growing diagonal shift),
/// then backtrack α = 1, ½, ¼, ... until E(x + αΔ) ≤ E(x) + 10⁻⁴ α gᵀΔ. When the decrease is
/// below E's round-off (see energy_scale) or backtracking fails, the full step is taken if it
/// lowers ‖g_free‖; otherwise Newton stops unconverged.
NewtonResult newton_minimize(const NewtonObjective& objective, const DofReduction& reduction,
                             SpdSolver& solver, const NewtonSettings& settings, VectorXd& x);

}  // namespace strata
