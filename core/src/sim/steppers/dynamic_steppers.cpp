#include "strata/core/sim/steppers/dynamic_steppers.hpp"

namespace strata {

namespace {

NewtonResult explicit_result() {
  NewtonResult result;
  result.converged = true;
  return result;
}

}  // namespace

BackwardEulerStepper::BackwardEulerStepper(const Problem& problem, const SolverSettings& settings)
    : m_integrator(problem, settings.newton.linear_solver,
                   newton_controls(settings, problem.has_obstacles())) {}

NewtonResult BackwardEulerStepper::step(double t0, double, double h, VectorXd& q, VectorXd& v) {
  VectorXd q_step = q, v_step = v;
  const NewtonResult result = m_integrator.step(t0, h, q_step, v_step);
  if (result.converged) {
    q.swap(q_step);
    v.swap(v_step);
  }
  return result;
}

NewtonResult SymplecticEulerStepper::step(double t0, double, double h, VectorXd& q, VectorXd& v) {
  symplectic_euler_step(m_problem, t0, h, q, v, &m_scratch);
  return explicit_result();
}

std::optional<std::pair<double, Index>> SymplecticEulerStepper::prepare_next_step(
    const VectorXd& q) {
  if (m_problem.mass_damping != 0.0 || m_problem.stiffness_damping != 0.0 ||
      !m_problem.model.is_identity())
    return std::nullopt;
  const std::pair<double, Index> smallest =
      m_problem.internal_forces_and_min_volume_ratio(q, m_scratch.forces);
  m_scratch.forces_current = true;
  return smallest;
}

NewtonResult Rk4Stepper::step(double t0, double, double h, VectorXd& q, VectorXd& v) {
  rk4_step(m_problem, t0, h, q, v);
  return explicit_result();
}

std::unique_ptr<TimeStepper> make_backward_euler_stepper(const Problem& problem,
                                                         const SolverSettings& settings) {
  return std::make_unique<BackwardEulerStepper>(problem, settings);
}

std::unique_ptr<TimeStepper> make_symplectic_euler_stepper(const Problem& problem,
                                                           const SolverSettings&) {
  return std::make_unique<SymplecticEulerStepper>(problem);
}

std::unique_ptr<TimeStepper> make_rk4_stepper(const Problem& problem, const SolverSettings&) {
  return std::make_unique<Rk4Stepper>(problem);
}

}  // namespace strata
