#pragma once
/// \file linear_solver.hpp
/// Sparse symmetric positive-definite solver for Newton systems, holding its factorisation state:
/// CHOLMOD supernodal Cholesky (symbolic analysis computed once and reused while the pattern stays
/// the same) or conjugate gradients preconditioned by incomplete Cholesky (for large meshes).
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

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
  LinearSolverKind m_kind;
  Index m_rows = -1;
  Index m_nonzeros = -1;
  long m_analyses = 0;
  long m_factorizations = 0;
  long m_cg_iterations = 0;
};

}  // namespace strata
