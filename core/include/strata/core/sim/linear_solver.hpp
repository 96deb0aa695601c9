#pragma once
/// \file linear_solver.hpp
/// Sparse symmetric positive-definite solver for Newton systems, holding its factorisation state:
/// CHOLMOD supernodal Cholesky (symbolic analysis computed once and reused while the pattern stays
/// the same) or conjugate gradients preconditioned by incomplete Cholesky (for large meshes).
///
/// Factor reuse (CHOLMOD): successive Newton matrices differ little, so a system is first solved
/// by conjugate gradients preconditioned with the last Cholesky factor (two triangular solves per
/// iteration), to a relative residual of 10⁻¹⁰; only when that does not converge within the
/// iterations one factorisation is worth (its flop count over the flops of one iteration, from
/// CHOLMOD's analysis, halved; at least 12, at most 60), or meets negative curvature, is A
/// factorised anew. Deterministic: the budget depends on the pattern only.
#include <memory>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/solver_settings.hpp"

namespace strata {

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

  LinearSolverKind kind() const { return m_kind; }
  long analyses() const { return m_analyses; }              ///< symbolic analyses so far
  long factorizations() const { return m_factorizations; }  ///< numeric factorisations so far
  long cg_iterations() const { return m_cg_iterations; }    ///< CG iterations so far
  /// Solves answered by CG on the previous factor (no factorisation).
  long reused_factor_solves() const { return m_reused_solves; }

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
  LinearSolverKind m_kind;
  Index m_rows = -1;
  Index m_nonzeros = -1;
  long m_analyses = 0;
  long m_factorizations = 0;
  long m_cg_iterations = 0;
  long m_reused_solves = 0;
  bool m_has_factor = false;
  int m_reuse_budget = 0;  ///< PCG iterations allowed before refactorising
  bool solve_with_previous_factor(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x);
};

}  // namespace strata
