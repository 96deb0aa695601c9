#pragma once
/// \file newton_solver.hpp
/// Newton's method with backtracking line search for minimising a sum of energy terms E(q) over
/// the free DOFs (Dirichlet DOFs keep their values). Used by backward Euler (incremental
/// potential) and static equilibrium (total potential energy).
///
/// Hessian: the exact Hessian where it is positive definite — tried first, so Newton converges
/// quadratically near a stable equilibrium; where it is not (past an instability: a compressed
/// body folding, a path past a bifurcation), the exact Hessian plus s·d·I, d its largest diagonal
/// entry, for the first s of 10⁻⁴ · 4ᵏ (then 1) whose solve succeeds and descends (the next
/// iteration starts at s/4); where none does, the PSD-projected one (per element), after which
/// the exact Hessian is skipped for 1, 2, 4, … iterations before it is tried again. Plain CG
/// (incomplete Cholesky) uses the projected Hessian only; multigrid-PCG tries the exact one and
/// refuses it on negative curvature.
///
/// Inexact Newton: the iterative linear solves (CG on a previous Cholesky factor, multigrid-PCG)
/// stop at a relative residual η_k that follows the Newton residual (Eisenstat–Walker; at most
/// 10⁻⁴, never tighter than needed to reach the target in one step); a fresh factorisation solves
/// exactly, incomplete-Cholesky CG keeps its own tolerance.
///
/// Convergence, whichever comes first:
///   - residual: ‖g_free‖ ≤ max(tolerance · force_scale, residual_floor);
///   - increment: a full Newton step (α = 1) with ‖Δq‖∞ ≤ increment_tolerance · displacement
///     scale, where the scale is ‖q − q_rest‖∞ (at least step_tolerance);
///   - stall: the line search cannot lower E and the full step cannot lower ‖g‖, while
///     ‖Δq‖∞ ≤ stall_tolerance · displacement scale (the residual is at its round-off level) or
///     ‖g_free‖ ≤ stall_residual_tolerance · force_scale (the residual is small against the
///     forces at work, e.g. on a symmetric path past a bifurcation, where the exact Hessian is
///     indefinite and the projected one gives no further decrease).
/// The last two are reported (`NewtonResult::criterion`) with the final residual.
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/dof_reduction.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/linear_solver.hpp"

namespace strata {

struct NewtonSettings {
  int max_iterations = 50;
  double tolerance = 1e-10;  ///< residual tolerance relative to force_scale
  double force_scale = 1.0;  ///< [N]
  /// Round-off level of the gradient [N] (see internal_force_roundoff); below it no iteration can
  /// make progress.
  double residual_floor = 0.0;
  /// Magnitude of the terms that make up E [J] (e.g. (2μ + λ)·volume for elastic energy): when
  /// the predicted decrease |gᵀΔ| is below 10⁻¹¹ × max(|E|, energy_scale), E cannot resolve it and
  /// the step is judged by the gradient norm instead.
  double energy_scale = 0.0;
  /// Absolute floor of the displacement scale [m] (round-off of positions, e.g. 10⁻¹⁴ × size).
  double step_tolerance = 0.0;
  /// Increment criterion relative to the displacement scale (0 disables it).
  double increment_tolerance = 1e-9;
  /// Largest relative increment at which a stalled residual counts as converged.
  double stall_tolerance = 1e-7;
  /// A stalled residual also counts as converged when ‖g_free‖ ≤ this × force_scale: far below
  /// what engineering solvers accept (CalculiX's default is 5·10⁻³ of the mean force), at a point
  /// where the line search can no longer resolve E. So does a solve that reaches max_iterations
  /// with its residual within this bound (still creeping at round-off).
  double stall_residual_tolerance = 1e-5;
  /// Try the exact Hessian first (solvers that detect indefiniteness).
  bool exact_hessian = true;
  /// Rest positions q_rest (3·#Q) for the displacement scale; empty: the scale is ‖q‖∞.
  const VectorXd* rest_positions = nullptr;
};

/// How a Newton solve ended.
enum class NewtonCriterion { none, residual, increment, stall };
std::string to_string(NewtonCriterion criterion);  ///< "none" | "residual" | "increment" | "stall"

/// Why a Newton solve that did not converge stopped: its iteration limit; a linear system no
/// diagonal shift made solvable; or no step along the Newton direction lowering the energy or
/// the gradient's norm (the residual stalled above every convergence bound).
enum class NewtonFailure { none, iteration_limit, linear_solve, no_descent };
/// "" | "the iteration limit" | "no solvable linear system" | "no step that lowers the energy or
/// its gradient"
std::string describe(NewtonFailure failure);

struct NewtonResult {
  bool converged = false;
  NewtonCriterion criterion = NewtonCriterion::none;
  int iterations = 0;
  int exact_hessian_iterations = 0;             ///< iterations solved with the exact Hessian
  int shifted_hessian_iterations = 0;           ///< … with the exact one plus a multiple of I
  int projected_hessian_iterations = 0;         ///< … with the PSD-projected one
  double residual = 0.0;                        ///< final ‖g_free‖ [N]
  double residual_target = 0.0;                 ///< the residual criterion's bound [N]
  NewtonFailure failure = NewtonFailure::none;  ///< why it stopped, when not converged
  std::vector<double> residuals;  ///< ‖g_free‖ at the start and after each iteration [N]
};

/// Round-off level of the elastic forces of `model` near the rest state [N]:
/// 10³ ε_machine · (2μ + λ) · h̄² · √(3·#V), with h̄ the mean rest edge length — the stress noise
/// of F ≈ I times a face area, accumulated over the DOFs.
double internal_force_roundoff(const EmbeddedElasticModel& model);

/// The matrices newton_minimize fills in every iteration. A caller that minimises the same
/// energy again and again (a time stepper) keeps one and passes it to each call: the Hessians'
/// patterns are then copied and their memory touched once, not once per call.
struct NewtonWorkspace {
  SparseMatrixd hessian;          ///< of the energy, all DOFs
  SparseMatrixd reduced_hessian;  ///< restricted to the free DOFs
  /// The energy, its Hessian pattern and the reduction the matrices were filled for; a call
  /// with any other starts afresh.
  const void* energy = nullptr;
  const void* pattern = nullptr;
  const void* reduction = nullptr;
};

/// Minimises `energy` from the initial guess `q` (3·#Q, updated in place). Each iteration:
/// gradient, Hessian (exact, else projected), reduce to free DOFs, solve H Δ = −g (on failure of
/// the projected system, retry with a growing diagonal shift), then backtrack α = 1, ½, ¼, ...
/// until E(q + αΔ) ≤ E(q) + 10⁻⁴ α gᵀΔ. When the decrease is below E's round-off (see
/// energy_scale) or backtracking fails, the full step is taken if it lowers ‖g_free‖.
/// `workspace`: kept between calls (see NewtonWorkspace); null: matrices local to this call.
NewtonResult newton_minimize(const EnergySum& energy, const DofReduction& reduction,
                             SpdSolver& solver, const NewtonSettings& settings, VectorXd& q,
                             NewtonWorkspace* workspace = nullptr);

}  // namespace strata
