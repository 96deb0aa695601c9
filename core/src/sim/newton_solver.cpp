#include "strata/core/sim/newton_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace strata {

namespace {

double largest_diagonal(const SparseMatrixd& H) {
  double largest = 0.0;
  for (Index i = 0; i < H.rows(); ++i)
    largest = std::max(largest, H.coeff(i, i));
  return largest;
}

/// H + shift · I.
SparseMatrixd shifted_matrix(const SparseMatrixd& H, double shift) {
  SparseMatrixd shifted = H;
  for (Index i = 0; i < H.rows(); ++i)
    shifted.coeffRef(i, i) += shift;
  return shifted;
}

/// Solves H Δ = rhs, adding τ I to H if it is not numerically positive definite.
bool solve_with_shift(SpdSolver& solver, SparseMatrixd& H, const VectorXd& rhs, VectorXd& step) {
  if (solver.solve(H, rhs, step)) return true;
  double shift = 1e-10 * std::max(largest_diagonal(H), 1e-300);
  for (int attempt = 0; attempt < 12; ++attempt, shift *= 10.0)
    if (solver.solve(shifted_matrix(H, shift), rhs, step)) return true;
  return false;
}

double displacement_scale(const NewtonSettings& settings, const VectorXd& q) {
  const double scale = settings.rest_positions != nullptr
                           ? (q - *settings.rest_positions).lpNorm<Eigen::Infinity>()
                           : q.lpNorm<Eigen::Infinity>();
  return std::max(scale, settings.step_tolerance);
}

/// Chooses the Hessian of each iteration: the exact one, or where it is not positive definite the
/// exact one shifted (solve_shifted_exact); where no shift makes it so, the PSD-projected one, with
/// an exponential back-off before the exact one is tried again. The next iteration starts at a
/// quarter of the shift that worked (as Levenberg–Marquardt's damping falls near a minimum), and at
/// the exact Hessian itself once that is below the first shift.
class HessianChoice {
 public:
  explicit HessianChoice(bool exact_allowed) : m_exact_allowed(exact_allowed) {}
  bool try_exact() const { return m_exact_allowed && m_skip == 0; }
  double first_shift() const { return m_shift; }
  void exact_solved(double shift) {
    m_shift = shift / kShiftFactor >= kFirstShift ? shift / kShiftFactor : 0.0;
  }
  void exact_failed() {
    m_backoff = std::max(1, 2 * m_backoff);
    m_skip = m_backoff;
    m_shift = 0.0;
  }
  void iteration_done() {
    if (m_skip > 0) --m_skip;
  }

  /// The shifts tried, relative to the Hessian's largest diagonal entry: 10⁻⁴ · 4ᵏ, and 1 last.
  static constexpr double kFirstShift = 1e-4;
  static constexpr double kShiftFactor = 4.0;
  static constexpr double kLastShift = 1.0;

 private:
  bool m_exact_allowed;
  int m_backoff = 0;
  int m_skip = 0;
  double m_shift = 0.0;
};

/// Solves (H + s·d·I) Δ = rhs with H the exact Hessian and d its largest diagonal entry, for the
/// first s of 0, 10⁻⁴, 4 · 10⁻⁴, 1.6 · 10⁻³, …, 0.41, 1 (from `first` on) whose solve succeeds and
/// descends (a solve answered without a factorisation, CG on a previous factor, does not prove the
/// matrix positive definite). Returns that s, or −1. Past an instability (a compressed body about
/// to fold, a symmetric path past a bifurcation) H has a few negative eigenvalues: the smallest
/// shift that makes it positive definite keeps its curvature everywhere else and leads along the
/// unstable directions, where the per-element projection discards the curvature of every element
/// compressed beyond its own stability and converges linearly at best.
double solve_shifted_exact(SpdSolver& solver, const SparseMatrixd& H, const VectorXd& rhs,
                           VectorXd& step, double first) {
  if (first == 0.0 && solver.solve(H, rhs, step) && rhs.dot(step) > 0.0) return 0.0;
  const double d = largest_diagonal(H);
  if (!(d > 0.0) || !std::isfinite(d)) return -1.0;
  for (double shift = std::max(first, HessianChoice::kFirstShift);;
       shift = std::min(shift * HessianChoice::kShiftFactor, HessianChoice::kLastShift)) {
    if (solver.solve_if_definite(shifted_matrix(H, shift * d), rhs, step) && rhs.dot(step) > 0.0)
      return shift;
    if (shift >= HessianChoice::kLastShift) return -1.0;
  }
}

/// Relative tolerance of each iterative linear solve (inexact Newton, Eisenstat & Walker 1996,
/// choice 2 with γ = 0.9, α = 2): η_k = γ (‖g_k‖ / ‖g_{k−1}‖)², at most kMaxForcing (and
/// kMaxForcing for the first solve); never tighter than needed to bring the residual to half the
/// target in one step, never tighter than 10⁻¹². (Their safeguard against η falling too fast only
/// acts above 0.1, which the cap excludes.) Near the solution η follows ‖g‖, which keeps Newton's
/// convergence quadratic.
class InexactNewtonForcing {
 public:
  static constexpr double kMaxForcing = 1e-4;
  explicit InexactNewtonForcing(double target) : m_target(target) {}
  double next(double residual) {
    double eta = kMaxForcing;
    if (m_previous_residual > 0.0) {
      const double ratio = residual / m_previous_residual;
      eta = std::min(0.9 * ratio * ratio, kMaxForcing);
    }
    if (residual > 0.0) eta = std::max(eta, std::min(0.5, 0.5 * m_target / residual));
    eta = std::max(eta, 1e-12);
    m_previous_residual = residual;
    return eta;
  }

 private:
  double m_target;
  double m_previous_residual = 0.0;
};

}  // namespace

std::string describe(NewtonFailure failure) {
  switch (failure) {
    case NewtonFailure::iteration_limit:
      return "the iteration limit";
    case NewtonFailure::linear_solve:
      return "no solvable linear system";
    case NewtonFailure::no_descent:
      return "no step that lowers the energy or its gradient";
    case NewtonFailure::none:
      break;
  }
  return "";
}

std::string to_string(NewtonCriterion criterion) {
  switch (criterion) {
    case NewtonCriterion::residual:
      return "residual";
    case NewtonCriterion::increment:
      return "increment";
    case NewtonCriterion::stall:
      return "stall";
    case NewtonCriterion::none:
      break;
  }
  return "none";
}

double internal_force_roundoff(const EmbeddedElasticModel& model) {
  const LameParameters lame = model.material().lame();
  const double h = model.mean_edge_length();
  return 1e3 * std::numeric_limits<double>::epsilon() * (2 * lame.mu + lame.lambda) * h * h *
         std::sqrt(static_cast<double>(model.num_dofs()));
}

NewtonResult newton_minimize(const EnergySum& objective, const DofReduction& reduction,
                             SpdSolver& solver, const NewtonSettings& settings, VectorXd& x,
                             NewtonWorkspace* workspace) {
  NewtonResult result;
  VectorXd gradient(x.size()), trial_gradient(x.size());
  NewtonWorkspace local;
  NewtonWorkspace& kept = workspace != nullptr ? *workspace : local;
  if (kept.energy != &objective || kept.pattern != &objective.pattern() ||
      kept.reduction != &reduction) {
    kept = NewtonWorkspace();
    kept.energy = &objective;
    kept.pattern = &objective.pattern();
    kept.reduction = &reduction;
  }
  SparseMatrixd& hessian = kept.hessian;
  SparseMatrixd& reduced_hessian = kept.reduced_hessian;
  VectorXd step;
  objective.gradient(x, gradient);
  VectorXd g = reduction.restrict_vector(gradient);
  result.residual = g.norm();
  result.residuals.push_back(result.residual);
  double energy = objective.value(x);
  const double target =
      std::max(settings.tolerance * settings.force_scale, settings.residual_floor);
  result.residual_target = target;
  HessianChoice choice(settings.exact_hessian && solver.detects_indefinite());
  auto finish = [&](NewtonCriterion criterion) {
    result.converged = true;
    result.criterion = criterion;
    return result;
  };
  InexactNewtonForcing forcing(target);
  while (true) {
    if (result.residual <= target || reduction.num_free() == 0)
      return finish(NewtonCriterion::residual);
    if (result.iterations >= settings.max_iterations) {
      // Out of iterations with the residual as small against the forces at work as a stall
      // accepts: a solve creeping at round-off, converged as a stall.
      if (result.iterations > 0 &&
          result.residual <= settings.stall_residual_tolerance * settings.force_scale)
        return finish(NewtonCriterion::stall);
      result.failure = NewtonFailure::iteration_limit;
      return result;
    }
    ++result.iterations;
    solver.set_relative_tolerance(forcing.next(result.residual));

    bool solved = false;
    const bool exact = choice.try_exact();
    if (exact) {
      objective.hessian(x, hessian, false);
      reduction.restrict_matrix(hessian, reduced_hessian);
      const double shift =
          solve_shifted_exact(solver, reduced_hessian, -g, step, choice.first_shift());
      solved = shift >= 0.0;
      if (!solved) {
        choice.exact_failed();
      } else {
        choice.exact_solved(shift);
        ++(shift > 0.0 ? result.shifted_hessian_iterations : result.exact_hessian_iterations);
      }
    }
    if (!solved) {
      objective.hessian(x, hessian, true);
      reduction.restrict_matrix(hessian, reduced_hessian);
      if (!solve_with_shift(solver, reduced_hessian, -g, step)) {
        result.failure = NewtonFailure::linear_solve;
        return result;
      }
      ++result.projected_hessian_iterations;
    }
    choice.iteration_done();
    VectorXd full_step = VectorXd::Zero(x.size());
    reduction.add_prolonged(step, full_step);
    // A barrier term may limit the step (it stays finite up to that fraction).
    const double alpha_max = objective.max_step(x, full_step);
    if (alpha_max < 1.0) {
      full_step *= alpha_max;
      step *= alpha_max;
    }
    const double increment = full_step.lpNorm<Eigen::Infinity>();

    const double slope = g.dot(step);
    double alpha = 1.0;
    VectorXd trial = x + full_step;
    double trial_energy = objective.value(trial);
    objective.gradient(trial, trial_gradient);
    VectorXd trial_g = reduction.restrict_vector(trial_gradient);
    // Near convergence the predicted energy change falls below E's round-off: decide by the
    // gradient norm then.
    const bool energy_is_noise =
        std::abs(slope) <= 1e-11 * std::max(std::abs(energy), settings.energy_scale);
    bool accepted =
        std::isfinite(trial_energy) && (energy_is_noise ? trial_g.norm() < result.residual
                                                        : trial_energy <= energy + 1e-4 * slope);
    while (!accepted && !energy_is_noise && alpha > 1e-10) {
      alpha *= 0.5;
      trial = x + alpha * full_step;
      trial_energy = objective.value(trial);
      accepted = std::isfinite(trial_energy) && trial_energy <= energy + 1e-4 * alpha * slope;
      if (accepted) {
        objective.gradient(trial, trial_gradient);
        trial_g = reduction.restrict_vector(trial_gradient);
      }
    }
    if (!accepted) {
      // Backtracking failed (E flat to round-off along Δ): take the full step if it lowers ‖g‖.
      alpha = 1.0;
      trial = x + full_step;
      trial_energy = objective.value(trial);
      objective.gradient(trial, trial_gradient);
      trial_g = reduction.restrict_vector(trial_gradient);
      if (!(std::isfinite(trial_energy) && trial_g.norm() < result.residual) && solved && exact) {
        // The exact Hessian's step fails where it is not positive definite along it: retry the
        // iteration with the projected Hessian before judging the residual stalled.
        choice.exact_failed();
        continue;
      }
      // E is at round-off along Δ but ‖g‖ is not: backtrack on ‖g‖ (stiff barrier and friction
      // terms make the full step overshoot long before E resolves the difference).
      for (double a = 0.5; energy_is_noise && a > 1e-6 &&
                           !(std::isfinite(trial_energy) && trial_g.norm() < result.residual);
           a *= 0.5) {
        alpha = a;
        trial = x + a * full_step;
        trial_energy = objective.value(trial);
        objective.gradient(trial, trial_gradient);
        trial_g = reduction.restrict_vector(trial_gradient);
      }
      if (!(std::isfinite(trial_energy) && trial_g.norm() < result.residual)) {
        // Nothing lowers E or ‖g‖: converged if the correction is at round-off level, or the
        // residual is already small against the forces at work (a symmetric state past a
        // bifurcation, whose exact Hessian is indefinite, stalls here).
        if (increment <= settings.stall_tolerance * displacement_scale(settings, x) ||
            result.residual <= settings.stall_residual_tolerance * settings.force_scale)
          return finish(NewtonCriterion::stall);
        result.failure = NewtonFailure::no_descent;
        return result;
      }
    }

    x = trial;
    energy = trial_energy;
    g = trial_g;
    result.residual = g.norm();
    result.residuals.push_back(result.residual);
    if (result.residual <= target) return finish(NewtonCriterion::residual);
    if (increment <= settings.step_tolerance) return finish(NewtonCriterion::increment);
    if (alpha == 1.0 && increment <= settings.increment_tolerance * displacement_scale(settings, x))
      return finish(NewtonCriterion::increment);
  }
}

}  // namespace strata
