#include "strata/core/sim/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>

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
      m_has_factor = false;
      // One factorisation costs `fl` flops, one PCG iteration about 4·nnz(L) + 4·nnz(A).
      const double factor_flops = m_impl->cholmod.cholmod().fl;
      const double iteration_flops =
          4.0 * m_impl->cholmod.cholmod().lnz + 4.0 * static_cast<double>(A.nonZeros());
      const double worth = iteration_flops > 0.0 ? 0.5 * factor_flops / iteration_flops : 0.0;
      m_reuse_budget = static_cast<int>(std::clamp(worth, 12.0, 60.0));
    }
    if (m_has_factor && solve_with_previous_factor(A, b, x)) {
      ++m_reused_solves;
      return true;
    }
    m_impl->cholmod.factorize(A);
    ++m_factorizations;
    m_has_factor = m_impl->cholmod.info() == Eigen::Success;
    if (!m_has_factor) return false;
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

bool SpdSolver::solve_with_previous_factor(const SparseMatrixd& A, ConstRef<VectorXd> b,
                                           VectorXd& x) {
  const double b_norm = b.norm();
  x.setZero(b.size());
  if (b_norm == 0.0) return true;
  const double target = 1e-10 * b_norm;
  VectorXd r = b;
  VectorXd z = m_impl->cholmod.solve(r);
  VectorXd p = z;
  VectorXd Ap(b.size());
  double rz = r.dot(z);
  for (int k = 0; k < m_reuse_budget; ++k) {
    Ap.noalias() = A.selfadjointView<Eigen::Lower>() * p;
    const double curvature = p.dot(Ap);
    if (!(curvature > 0.0) || !(rz > 0.0)) return false;  // not positive definite along p
    const double alpha = rz / curvature;
    x += alpha * p;
    r -= alpha * Ap;
    ++m_cg_iterations;
    if (r.norm() <= target) {
      // A factor that needed more than a third of its budget is refreshed at the next solve.
      if (3 * (k + 1) > m_reuse_budget) m_has_factor = false;
      return x.allFinite();
    }
    z = m_impl->cholmod.solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return false;
}

}  // namespace strata
