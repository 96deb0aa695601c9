#include "strata/core/sim/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

#include "strata/core/common/vector_chunks.hpp"
#include "strata/core/sim/algebraic_multigrid.hpp"

namespace strata {

/// The preconditioner of the multigrid path: one cycle over the tree's levels or BoomerAMG's.
struct SpdSolver::Cycle {
  virtual ~Cycle() = default;
  /// Builds the levels for A; false when the coarsest operator does not factorise.
  virtual bool setup(const SparseMatrixd& A) = 0;
  /// Uses A (same pattern) on the finest level from now on, where the cycle can.
  virtual void update_finest(const SparseMatrixd& A) = 0;
  virtual void apply(ConstRef<VectorXd> r, VectorXd& z) const = 0;
  /// y = A x for the A of the last setup() or update_finest(), then `after` on fixed ranges of
  /// y's rows; returns the sum of its values (MultigridPreconditioner::multiply_finest).
  virtual double multiply(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                          const std::function<double(Index, Index)>& after) const = 0;
  /// MultigridPreconditioner::widen_smoother_intervals.
  virtual void widen_smoother_intervals() = 0;
  virtual double setup_seconds() const = 0;
  virtual int num_levels() const = 0;
  /// MultigridPreconditioner::smoother_estimates, seed_smoother_estimates and seeded_setup, where
  /// the cycle's levels are the tree's (the algebraic cycle's are rebuilt with their system).
  virtual std::vector<SmootherEstimate> smoother_estimates() const { return {}; }
  virtual void seed_smoother_estimates(std::vector<SmootherEstimate> /*estimates*/) {}
  /// Whether the last setup took anything of a previous hierarchy (seeded estimates or its coarse
  /// levels).
  virtual bool seeded_setup() const { return false; }
  /// MultigridPreconditioner::release_coarse_levels, offer_coarse_levels, carried_setup and
  /// carried_iterations_per_decade (the tree's levels only).
  virtual std::shared_ptr<MultigridCoarseLevels> release_coarse_levels(double /*rate*/) {
    return nullptr;
  }
  virtual void offer_coarse_levels(std::shared_ptr<MultigridCoarseLevels> /*levels*/) {}
  virtual bool carried_setup() const { return false; }
  virtual double carried_iterations_per_decade() const { return -1.0; }
};

namespace {

struct TreeCycle final : SpdSolver::Cycle {
  MultigridPreconditioner preconditioner;
  TreeCycle(std::vector<SparseMatrixd> prolongations, const MultigridOptions& options,
            std::vector<std::vector<std::int64_t>> coarse_keys)
      : preconditioner(std::move(prolongations), options, std::move(coarse_keys)) {}
  bool setup(const SparseMatrixd& A) override { return preconditioner.setup(A); }
  void update_finest(const SparseMatrixd& A) override { preconditioner.update_finest(A); }
  void apply(ConstRef<VectorXd> r, VectorXd& z) const override { preconditioner.apply(r, z); }
  double multiply(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                  const std::function<double(Index, Index)>& after) const override {
    return preconditioner.multiply_finest(A, x, y, after);
  }
  void widen_smoother_intervals() override { preconditioner.widen_smoother_intervals(); }
  double setup_seconds() const override { return preconditioner.setup_seconds(); }
  int num_levels() const override { return preconditioner.num_levels(); }
  std::vector<SmootherEstimate> smoother_estimates() const override {
    return preconditioner.smoother_estimates();
  }
  void seed_smoother_estimates(std::vector<SmootherEstimate> estimates) override {
    preconditioner.seed_smoother_estimates(std::move(estimates));
  }
  bool seeded_setup() const override {
    return preconditioner.seeded_setup() || preconditioner.carried_setup();
  }
  std::shared_ptr<MultigridCoarseLevels> release_coarse_levels(double rate) override {
    return preconditioner.release_coarse_levels(rate);
  }
  void offer_coarse_levels(std::shared_ptr<MultigridCoarseLevels> levels) override {
    preconditioner.offer_coarse_levels(std::move(levels));
  }
  bool carried_setup() const override { return preconditioner.carried_setup(); }
  double carried_iterations_per_decade() const override {
    return preconditioner.carried_iterations_per_decade();
  }
};

/// BoomerAMG's coarse spaces with strata's cycle: the interpolations come from hypre (once per
/// system size; later setups keep them), the Galerkin products, Chebyshev smoothers and coarsest
/// factorisation are those of the tree's multigrid, on TBB threads.
struct AlgebraicCycle final : SpdSolver::Cycle {
  std::vector<Index> free_dofs;           ///< of the systems; empty: every vertex whole
  const MultigridOptions* cycle_options;  ///< the solver's, read when the cycle is built
  std::unique_ptr<MultigridPreconditioner> cycle;
  Index rows = -1;
  double seconds = 0.0;

  AlgebraicCycle(std::vector<Index> dofs, const MultigridOptions* options)
      : free_dofs(std::move(dofs)), cycle_options(options) {}
  bool setup(const SparseMatrixd& A) override {
    const auto start = std::chrono::steady_clock::now();
    bool ok = true;
    if (cycle == nullptr || rows != A.rows()) {
      cycle.reset();
      // Rows that are not the free DOFs given (another size) are taken as whole vertices; a
      // system that cannot be is left to CHOLMOD (setup fails).
      AlgebraicMultigridOptions options;
      if (static_cast<Index>(free_dofs.size()) == A.rows())
        options.row_dofs = free_dofs;
      else if (A.rows() % 3 != 0)
        return false;
      AlgebraicMultigrid amg(options);
      ok = amg.setup(A);
      std::vector<SparseMatrixd> prolongations;
      if (ok) prolongations = amg.prolongations();
      ok = ok && !prolongations.empty();  // too small to coarsen
      if (ok) {
        cycle = std::make_unique<MultigridPreconditioner>(std::move(prolongations), *cycle_options);
        rows = A.rows();
      }
    }
    ok = ok && cycle->setup(A);
    if (!ok) cycle.reset();  // hypre's spaces of a matrix that failed are not kept
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return ok;
  }
  void update_finest(const SparseMatrixd& A) override { cycle->update_finest(A); }
  void widen_smoother_intervals() override { cycle->widen_smoother_intervals(); }
  void apply(ConstRef<VectorXd> r, VectorXd& z) const override { cycle->apply(r, z); }
  double multiply(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                  const std::function<double(Index, Index)>& after) const override {
    if (cycle != nullptr) return cycle->multiply_finest(A, x, y, after);
    return symmetric_product(A, x, y, after);
  }
  double setup_seconds() const override { return seconds; }
  int num_levels() const override { return cycle != nullptr ? cycle->num_levels() : 0; }
};

}  // namespace

struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrixd, Eigen::Lower> cholmod;
  Eigen::ConjugateGradient<SparseMatrixd, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      cg;
};

SpdSolver::SpdSolver(LinearSolverKind kind)
    : m_impl(std::make_unique<Impl>()),
      m_requested(kind),
      m_kind(kind == LinearSolverKind::cg ? kind : LinearSolverKind::cholmod) {
  m_choose_by_size = kind == LinearSolverKind::automatic;
  if (kind == LinearSolverKind::amg) use_algebraic_multigrid();
  m_impl->cg.setTolerance(1e-12);
  // A failed factorisation is an expected outcome (Newton then projects the Hessian): no
  // CHOLMOD warning on stderr.
  m_impl->cholmod.cholmod().print = 0;
}

SpdSolver::~SpdSolver() = default;

void SpdSolver::use_nested_spaces(const NestedSpaces* spaces, const std::vector<Index>& free_dofs,
                                  std::vector<SmootherEstimate> smoother_estimates,
                                  std::shared_ptr<MultigridCoarseLevels> coarse_levels) {
  const LinearSolverKind requested = m_requested;
  m_rows = m_nonzeros = m_multigrid_rows = m_multigrid_nonzeros = -1;
  m_has_factor = false;
  m_multigrid.reset();
  m_multigrid_stale = true;
  const bool has_levels = spaces != nullptr && !spaces->empty();
  const bool multigrid =
      has_levels && (requested == LinearSolverKind::multigrid ||
                     (requested == LinearSolverKind::automatic &&
                      static_cast<Index>(free_dofs.size()) >= kMultigridMinDofs));
  m_choose_by_size = false;
  m_free_dofs = free_dofs;
  if (multigrid) {
    m_kind = LinearSolverKind::multigrid;
    std::vector<std::vector<std::int64_t>> keys;
    std::vector<SparseMatrixd> prolongations = free_dof_prolongations(*spaces, free_dofs, &keys);
    m_multigrid =
        std::make_unique<TreeCycle>(std::move(prolongations), m_cycle_options, std::move(keys));
    if (!smoother_estimates.empty())
      m_multigrid->seed_smoother_estimates(std::move(smoother_estimates));
    if (coarse_levels != nullptr) m_multigrid->offer_coarse_levels(std::move(coarse_levels));
  } else if (requested == LinearSolverKind::amg) {
    use_algebraic_multigrid();
  } else if (requested == LinearSolverKind::automatic) {
    m_kind = LinearSolverKind::cholmod;
    m_choose_by_size = true;
  } else {
    m_kind = requested == LinearSolverKind::cg ? LinearSolverKind::cg : LinearSolverKind::cholmod;
  }
}

void SpdSolver::use_algebraic_multigrid() {
  m_kind = LinearSolverKind::amg;
  m_multigrid = std::make_unique<AlgebraicCycle>(m_free_dofs, &m_cycle_options);
  m_multigrid_stale = true;
}

int SpdSolver::multigrid_levels() const {
  return m_multigrid != nullptr ? m_multigrid->num_levels() : 0;
}

std::vector<SmootherEstimate> SpdSolver::smoother_estimates() const {
  if (m_multigrid == nullptr || m_multigrid_setups == 0) return {};
  return m_multigrid->smoother_estimates();
}

std::shared_ptr<MultigridCoarseLevels> SpdSolver::release_coarse_levels() {
  if (m_multigrid == nullptr || m_multigrid_setups == 0 || m_multigrid_stale) return nullptr;
  std::shared_ptr<MultigridCoarseLevels> levels =
      m_multigrid->release_coarse_levels(m_iterations_per_decade);
  if (levels != nullptr) m_multigrid_stale = true;
  return levels;
}

bool SpdSolver::solve_if_definite(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  struct Probing {
    bool& flag;
    explicit Probing(bool& f) : flag(f) { flag = true; }
    ~Probing() { flag = false; }
  } probing(m_probing);
  return solve(A, b, x);
}

bool SpdSolver::solve(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  if (A.rows() == 0) {
    x.resize(0);
    return true;
  }
  if (m_choose_by_size) choose_by_size(A);
  if (m_kind == LinearSolverKind::multigrid || m_kind == LinearSolverKind::amg)
    return solve_multigrid(A, b, x);
  if (m_kind == LinearSolverKind::cholmod) return solve_cholmod(A, b, x);
  m_impl->cg.setMaxIterations(std::max<Index>(1000, 10 * A.rows()));
  m_impl->cg.compute(A);
  ++m_factorizations;
  if (m_impl->cg.info() != Eigen::Success) return false;
  x = m_impl->cg.solve(b);
  m_cg_iterations += m_impl->cg.iterations();
  return m_impl->cg.info() == Eigen::Success && x.allFinite();
}

void SpdSolver::analyze(const SparseMatrixd& A) {
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
  m_factor_flops_per_nonzero = factor_flops / std::max(1.0, static_cast<double>(A.nonZeros()));
}

void SpdSolver::choose_by_size(const SparseMatrixd& A) {
  m_choose_by_size = false;
  if (A.rows() < kAlgebraicMultigridMinDofs) return;
  analyze(A);  // kept: CHOLMOD is also the fallback of algebraic multigrid
  if (m_factor_flops_per_nonzero >= kAlgebraicMultigridMinFill) use_algebraic_multigrid();
}

bool SpdSolver::solve_cholmod(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  if (A.rows() != m_rows || A.nonZeros() != m_nonzeros) analyze(A);
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

bool SpdSolver::solve_with_previous_factor(const SparseMatrixd& A, ConstRef<VectorXd> b,
                                           VectorXd& x) {
  const double b_norm = b.norm();
  x.setZero(b.size());
  if (b_norm == 0.0) return true;
  const double target = m_relative_tolerance * b_norm;
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

bool SpdSolver::solve_multigrid(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  if (A.rows() != m_multigrid_rows || A.nonZeros() != m_multigrid_nonzeros) {
    m_multigrid_rows = A.rows();
    m_multigrid_nonzeros = A.nonZeros();
    m_multigrid_stale = true;
  }
  auto setup = [&] {
    ++m_multigrid_setups;
    ++m_factorizations;
    const bool ok = m_multigrid->setup(A);
    m_multigrid_setup_seconds += m_multigrid->setup_seconds();
    m_multigrid_stale = !ok;
    // Carried coarse levels keep the reference rate of the hierarchy that computed them.
    if (m_multigrid->carried_setup()) ++m_carried_setups;
    m_iterations_per_decade =
        m_multigrid->carried_setup() ? m_multigrid->carried_iterations_per_decade() : -1.0;
    return ok;
  };
  // Multigrid could not solve this system: CHOLMOD decides. If A factorises, multigrid is not up
  // to this problem and CHOLMOD takes every later solve; if not, A is indefinite (Newton then
  // projects) and multigrid stays for the next matrix.
  auto direct = [&] {
    m_multigrid_stale = true;
    if (m_probing) return false;
    ++m_direct_fallbacks;
    if (!solve_cholmod(A, b, x)) return false;
    m_kind = LinearSolverKind::cholmod;
    m_multigrid.reset();
    return true;
  };
  bool fresh = false;
  if (m_multigrid_stale) {
    if (!setup()) return direct();  // the coarsest Galerkin operator does not factorise
    fresh = true;
  } else {
    m_multigrid->update_finest(A);
  }
  // A V-cycle found indefinite: a smoother's eigenvalue estimate missed the top of the spectrum;
  // the smoothers widened to the row-sum bound try once more.
  auto pcg = [&] {
    int result = multigrid_pcg(A, b, x);
    if (result == -3) {
      m_multigrid->widen_smoother_intervals();
      result = multigrid_pcg(A, b, x);
    }
    return result == -3 ? -1 : result;
  };
  int iterations = pcg();
  if (iterations == -1 && (!fresh || m_multigrid->seeded_setup())) {
    // Stale coarse levels, or smoothers on a previous system's estimates: set up on this matrix,
    // measuring the estimates, and try once more.
    if (!setup()) return direct();
    iterations = pcg();
  }
  if (iterations == -1) return direct();  // no convergence on a fresh hierarchy
  if (iterations < 0) {                   // negative curvature: A is not positive definite
    m_multigrid_stale = true;
    return false;
  }
  // Staleness in iterations per decade of residual reduction (tolerances differ between solves).
  if (iterations > 0) {
    const double decades = std::max(1.0, -std::log10(m_relative_tolerance));
    const double rate = iterations / decades;
    if (m_iterations_per_decade < 0.0)
      m_iterations_per_decade = rate;
    else if (rate > 2.0 * m_iterations_per_decade + 1.0)
      m_multigrid_stale = true;
  }
  return true;
}

int SpdSolver::multigrid_pcg(const SparseMatrixd& A, ConstRef<VectorXd> b, VectorXd& x) {
  // The vector updates run over fixed chunks in parallel, fused with the product where they can
  // (vector_chunks.hpp): the iterates are the same at any thread count.
  const Index n = b.size();
  const double b_norm = std::sqrt(chunked_dot(b, b));
  x.setZero(n);
  if (b_norm == 0.0) return 0;
  const double target = m_relative_tolerance * b_norm;
  VectorXd r = b;
  VectorXd z(n), Ap(n);
  m_multigrid->apply(r, z);
  VectorXd p = z;
  double rz = chunked_dot(r, z);
  for (int k = 0; k < m_max_iterations; ++k) {
    const double curvature = m_multigrid->multiply(A, p, Ap, [&](Index begin, Index end) {
      return p.segment(begin, end - begin).dot(Ap.segment(begin, end - begin));
    });
    if (!(rz > 0.0)) return -3;  // the preconditioner, not A, is not positive definite
    if (!(curvature > 0.0)) return -2;
    const double alpha = rz / curvature;
    const double r_squared = sum_over_vector_chunks(n, [&](Index begin, Index end) {
      const Index m = end - begin;
      x.segment(begin, m) += alpha * p.segment(begin, m);
      r.segment(begin, m) -= alpha * Ap.segment(begin, m);
      return r.segment(begin, m).squaredNorm();
    });
    ++m_cg_iterations;
    if (std::sqrt(r_squared) <= target) return x.allFinite() ? k + 1 : -1;
    m_multigrid->apply(r, z);
    const double rz_next = chunked_dot(r, z);
    const double beta = rz_next / rz;
    for_each_vector_chunk(n, [&](Index begin, Index end) {
      p.segment(begin, end - begin) =
          z.segment(begin, end - begin) + beta * p.segment(begin, end - begin);
    });
    rz = rz_next;
  }
  return -1;
}

}  // namespace strata
