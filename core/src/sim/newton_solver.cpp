#include "strata/core/sim/newton_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "strata/core/sim/stable_time_step.hpp"

namespace strata {

namespace {

/// Solves H Δ = rhs, adding τ I to H if it is not numerically positive definite.
bool solve_with_shift(SpdSolver& solver, SparseMatrixd& H, const VectorXd& rhs, VectorXd& step) {
  if (solver.solve(H, rhs, step)) return true;
  double max_diagonal = 0.0;
  for (Index i = 0; i < H.rows(); ++i)
    max_diagonal = std::max(max_diagonal, H.coeff(i, i));
  double shift = 1e-10 * std::max(max_diagonal, 1e-300);
  for (int attempt = 0; attempt < 12; ++attempt, shift *= 10.0) {
    SparseMatrixd shifted = H;
    for (Index i = 0; i < H.rows(); ++i)
      shifted.coeffRef(i, i) += shift;
    if (solver.solve(shifted, rhs, step)) return true;
  }
  return false;
}

}  // namespace

double internal_force_roundoff(const EmbeddedElasticModel& model) {
  const LameParameters lame = model.material().lame();
  const double h = model.mean_edge_length();
  return 1e3 * std::numeric_limits<double>::epsilon() * (2 * lame.mu + lame.lambda) * h * h *
         std::sqrt(static_cast<double>(model.num_dofs()));
}

NewtonResult newton_minimize(const NewtonObjective& objective, const DofReduction& reduction,
                             SpdSolver& solver, const NewtonSettings& settings, VectorXd& x) {
  NewtonResult result;
  VectorXd gradient(x.size()), trial_gradient(x.size());
  SparseMatrixd hessian, reduced_hessian;
  VectorXd step;
  objective.gradient(x, gradient);
  VectorXd g = reduction.restrict_vector(gradient);
  result.residual = g.norm();
  double energy = objective.energy(x);
  const double target =
      std::max(settings.tolerance * settings.force_scale, settings.residual_floor);
  while (true) {
    if (result.residual <= target || reduction.num_free() == 0) {
      result.converged = true;
      return result;
    }
    if (result.iterations >= settings.max_iterations) return result;
    ++result.iterations;

    objective.hessian(x, hessian);
    reduction.restrict_matrix(hessian, reduced_hessian);
    if (!solve_with_shift(solver, reduced_hessian, -g, step)) return result;
    VectorXd full_step = VectorXd::Zero(x.size());
    reduction.add_prolonged(step, full_step);

    const double slope = g.dot(step);
    double alpha = 1.0;
    VectorXd trial = x + full_step;
    double trial_energy = objective.energy(trial);
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
      trial_energy = objective.energy(trial);
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
      trial_energy = objective.energy(trial);
      objective.gradient(trial, trial_gradient);
      trial_g = reduction.restrict_vector(trial_gradient);
      if (!(std::isfinite(trial_energy) && trial_g.norm() < result.residual)) return result;
    }

    x = trial;
    energy = trial_energy;
    g = trial_g;
    result.residual = g.norm();
    if (full_step.lpNorm<Eigen::Infinity>() <= settings.step_tolerance) {
      result.converged = true;
      return result;
    }
  }
}

}  // namespace strata
