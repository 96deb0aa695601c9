#pragma once
/// \file linear_solver.hpp
/// Sparse symmetric positive-definite solver for Newton systems, holding its factorisation state:
/// CHOLMOD supernodal Cholesky (symbolic analysis computed once and reused while the pattern stays
/// the same) or conjugate gradients preconditioned by incomplete Cholesky (for large meshes).
///
/// Factor reuse (CHOLMOD): successive Newton matrices differ little, so a system is first solved
/// by conjugate gradients preconditioned with the last Cholesky factor (two triangular solves per
/// iteration), to the relative tolerance (set_relative_tolerance); only when that does not converge
/// within the iterations one factorisation is worth (its flop count over the flops of one
/// iteration, from CHOLMOD's analysis, halved; at least 12, at most 60), or meets negative
/// curvature, is A factorised anew. Deterministic: the budget depends on the pattern only.
///
/// Multigrid (multigrid.hpp): CG preconditioned by a V-cycle over nested coarser spaces, to the
/// relative tolerance. The coarse operators of one setup serve the following solves
/// (Newton matrices of one step, and of later steps, are close) until a solve needs more than
/// twice the iterations per decade of residual reduction of the first solve after the setup
/// (plus one), fails, or meets negative curvature; then the next solve sets up anew. A setup that
/// kept a previous solver's coarse levels (use_nested_spaces) compares with the first solve after
/// the setup that computed them, and one that fails to converge is set up anew before CHOLMOD is
/// asked. The finest
/// level's smoother always uses the current matrix. When multigrid cannot solve a system (no
/// convergence within 500 iterations on a fresh hierarchy, or a coarsest operator that does not
/// factorise), CHOLMOD solves it (counted, direct_fallbacks): if A factorises, CHOLMOD takes every
/// later solve (kind() becomes cholmod); if not, A is indefinite and the solve fails.
///
/// Algebraic multigrid takes the same path with coarse spaces from hypre's BoomerAMG
/// (algebraic_multigrid.hpp) in place of the tree's levels: its interpolations are computed at the
/// first setup for a system size and kept; every setup recomputes the Galerkin products, and the
/// cycle, PCG, staleness rule and CHOLMOD fallback are the tree's.
#include <memory>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/multigrid.hpp"
#include "strata/core/sim/solver_settings.hpp"

namespace strata {

/// Free DOFs from which `automatic` picks multigrid over CHOLMOD (when coarser levels exist).
inline constexpr Index kMultigridMinDofs = 8000;
/// Without coarser levels, `automatic` picks algebraic multigrid over CHOLMOD for systems of at
/// least kAlgebraicMultigridMinDofs free DOFs whose Cholesky factorisation (CHOLMOD's symbolic
/// analysis) costs at least kAlgebraicMultigridMinFill flops per non-zero of A: compact 3D bodies
/// from about 30k vertices (a 30³-cell cube), not slender ones, whose separators stay small.
inline constexpr Index kAlgebraicMultigridMinDofs = 20000;
inline constexpr double kAlgebraicMultigridMinFill = 20000.0;

class SpdSolver {
 public:
  explicit SpdSolver(LinearSolverKind kind);
  ~SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;

  /// Solves A x = b. `A` is symmetric (both triangles stored), compressed; its pattern must stay
  /// the same between calls (a change of size or non-zero count triggers a new analysis). Returns
  /// false if A is not numerically positive definite (CHOLMOD) or CG did not converge.
  bool solve(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
  /// The same, for a system that may be indefinite (Newton's shifted Hessians): where multigrid
  /// does not converge it returns false instead of turning to CHOLMOD (which would factorise,
  /// and take every later solve, only for a matrix that turned out positive definite).
  bool solve_if_definite(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);

  /// Resolves `automatic` and `multigrid` for a system with these free DOFs (ascending indices
  /// into 3 · spaces->num_fine_vertices()) and, when multigrid is chosen, builds its transfers.
  /// `spaces` may be null or empty (no coarser levels): then `multigrid` is CHOLMOD and
  /// `automatic` chooses between CHOLMOD and algebraic multigrid at the first solve, by the
  /// system's size and its factorisation's cost (kAlgebraicMultigridMinFill). Without this call
  /// `multigrid` is CHOLMOD, `automatic` chooses the same way, and algebraic multigrid takes the
  /// systems' rows as whole vertices (x, y, z); a system whose row count is not a multiple of 3
  /// then goes to CHOLMOD.
  /// `smoother_estimates` (from a previous hierarchy: smoother_estimates()) seed the first setup
  /// of the tree's multigrid (MultigridPreconditioner::seed_smoother_estimates); should PCG not
  /// converge on that hierarchy, it is set up again with measured estimates before CHOLMOD is
  /// asked.
  /// `coarse_levels` (a previous solver's release_coarse_levels()) are offered to that first
  /// setup (MultigridPreconditioner::offer_coarse_levels): where the coarse spaces are the same,
  /// it sets up only the finest level, and the hierarchy counts as stale once PCG needs more than
  /// twice the iterations per decade of residual reduction, plus one, that it needed on the
  /// hierarchy that computed those levels.
  void use_nested_spaces(const NestedSpaces* spaces, const std::vector<Index>& free_dofs,
                         std::vector<SmootherEstimate> smoother_estimates = {},
                         std::shared_ptr<MultigridCoarseLevels> coarse_levels = {});

  /// Relative residual ‖b − A x‖ / ‖b‖ at which the iterative paths (CG on a previous factor,
  /// multigrid-PCG) stop; default 10⁻¹⁰. Newton sets it per solve (inexact Newton).
  void set_relative_tolerance(double tolerance) { m_relative_tolerance = tolerance; }
  double relative_tolerance() const { return m_relative_tolerance; }
  /// Iteration limit of multigrid-PCG (default 500) before it falls back to CHOLMOD.
  void set_max_iterations(int iterations) { m_max_iterations = iterations; }
  /// The options of the multigrid cycles: the tree's cycle built by a later use_nested_spaces(),
  /// the algebraic one at its next hierarchy (a new system size).
  void set_multigrid_options(const MultigridOptions& options) { m_cycle_options = options; }

  /// The solver in use (never `automatic`).
  LinearSolverKind kind() const { return m_kind; }
  /// Whether a failed solve proves the matrix indefinite (CHOLMOD), or at least negative
  /// curvature is detected (multigrid-PCG): Newton may then try the exact Hessian.
  bool detects_indefinite() const { return m_kind != LinearSolverKind::cg; }
  /// Multigrid setups (Galerkin products and coarsest factorisation, or algebraic hierarchies)
  /// so far.
  long multigrid_setups() const { return m_multigrid_setups; }
  /// Multigrid solves that did not converge on a fresh hierarchy and were solved by CHOLMOD.
  long direct_fallbacks() const { return m_direct_fallbacks; }
  /// Wall time of all multigrid setups so far [s].
  double multigrid_setup_seconds() const { return m_multigrid_setup_seconds; }
  /// Levels of the multigrid hierarchy (0 unless multigrid).
  int multigrid_levels() const;
  /// The smoothers' Lanczos estimates of the tree's multigrid as of its last setup (empty for
  /// other solvers or before a setup).
  std::vector<SmootherEstimate> smoother_estimates() const;
  /// The coarse levels of the tree multigrid's last setup, given up for a solver built next on a
  /// nearby system (use_nested_spaces); this solver sets up anew at its next solve. Null for
  /// other solvers, before a setup, or when the hierarchy is due to be set up anew.
  std::shared_ptr<MultigridCoarseLevels> release_coarse_levels();
  /// Setups that took a previous solver's coarse levels (counted in multigrid_setups too).
  long carried_setups() const { return m_carried_setups; }
  /// Flops of a Cholesky factorisation per non-zero of A, from the last symbolic analysis (0
  /// before any): the cost `automatic` compares with kAlgebraicMultigridMinFill.
  double factor_flops_per_nonzero() const { return m_factor_flops_per_nonzero; }
  long analyses() const { return m_analyses; }              ///< symbolic analyses so far
  long factorizations() const { return m_factorizations; }  ///< numeric factorisations so far
  long cg_iterations() const { return m_cg_iterations; }    ///< CG iterations so far
  /// Solves answered by CG on the previous factor (no factorisation).
  long reused_factor_solves() const { return m_reused_solves; }

  /// The multigrid path's preconditioner, the tree's cycle or BoomerAMG's (defined in the source).
  struct Cycle;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
  LinearSolverKind m_requested;
  LinearSolverKind m_kind;
  Index m_rows = -1;
  Index m_nonzeros = -1;
  long m_analyses = 0;
  long m_factorizations = 0;
  long m_cg_iterations = 0;
  long m_reused_solves = 0;
  bool m_has_factor = false;
  int m_reuse_budget = 0;                   ///< PCG iterations allowed before refactorising
  double m_factor_flops_per_nonzero = 0.0;  ///< of the last analysis
  double m_relative_tolerance = 1e-10;
  int m_max_iterations = 500;
  MultigridOptions m_cycle_options;
  Index m_multigrid_rows = -1;
  Index m_multigrid_nonzeros = -1;
  long m_direct_fallbacks = 0;
  bool m_probing = false;  ///< in solve_if_definite: no direct fallback
  long m_multigrid_setups = 0;
  long m_carried_setups = 0;
  double m_multigrid_setup_seconds = 0.0;
  bool m_multigrid_stale = true;
  double m_iterations_per_decade = -1.0;  ///< of the first solve after the last setup
  bool m_choose_by_size = false;          ///< `automatic` without nested spaces: decided at a solve
  std::vector<Index> m_free_dofs;  ///< of the systems (use_nested_spaces); empty: whole vertices
  std::unique_ptr<Cycle> m_multigrid;
  void use_algebraic_multigrid();
  void analyze(const SparseMatrixd& A);         ///< CHOLMOD's symbolic analysis of A's pattern
  void choose_by_size(const SparseMatrixd& A);  ///< `automatic` without nested spaces
  bool solve_with_previous_factor(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
  bool solve_cholmod(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
  bool solve_multigrid(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
  /// PCG with the V-cycle; returns iterations, or −1 (no convergence), −2 (negative curvature of
  /// A), −3 (the V-cycle is not positive definite).
  int multigrid_pcg(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
};

}  // namespace strata
