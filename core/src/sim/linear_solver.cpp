#include "strata/core/sim/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>

namespace strata {

struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrixd, Eigen::Lower> cholmod;
  Eigen::ConjugateGradient<SparseMatrixd, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      cg;
};

SpdSolver::SpdSolver(LinearSolverKind kind) : m_impl(std::make_unique<Impl>()), m_kind(kind) {
  m_impl->cg.setTolerance(1e-12);
  // A failed factorisation is an expected outcome (Newton then projects the Hessian): no
  // CHOLMOD warning on stderr.
  m_impl->cholmod.cholmod().print = 0;
}

SpdSolver::~SpdSolver() = default;

bool SpdSolver::solve(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  if (A.rows() == 0) {
    x.resize(0);
    return true;
  }
  if (m_kind == LinearSolverKind::cholmod) {
    if (A.rows() != m_rows || A.nonZeros() != m_nonzeros) {
      m_impl->cholmod.analyzePattern(A);
      m_rows = A.rows();
      m_nonzeros = A.nonZeros();
      ++m_analyses;
    }
    m_impl->cholmod.factorize(A);
    ++m_factorizations;
    if (m_impl->cholmod.info() != Eigen::Success) return false;
    x = m_impl->cholmod.solve(b);
    return m_impl->cholmod.info() == Eigen::Success && x.allFinite();
  }
  m_impl->cg.setMaxIterations(std::max<Index>(1000, 10 * A.rows()));
  m_impl->cg.compute(A);
  ++m_factorizations;
  if (m_impl->cg.info() != Eigen::Success) return false;
  x = m_impl->cg.solve(b);
  m_cg_iterations += m_impl->cg.iterations();
  return m_impl->cg.info() == Eigen::Success && x.allFinite();
}

}  // namespace strata
