#include "strata/core/sim/steppers/static_load_stepper.hpp"

#include <cmath>

namespace strata {

StaticLoadStepper::StaticLoadStepper(const Problem& problem, const SolverSettings& settings)
    : m_problem(problem),
      m_solver(problem, settings.newton.linear_solver,
               newton_controls(settings, problem.has_obstacles())) {}

NewtonResult StaticLoadStepper::step(double, double t1, double, VectorXd& q, VectorXd& v) {
  VectorXd guess = q;
  if (m_has_previous) guess += q - m_previous;  // linear extrapolation along the load path
  if (m_problem.has_obstacles()) {
    m_solver.set_contact_reference(q);
    // The barrier needs a start inside its domain: no extrapolation into an obstacle.
    if (!std::isfinite(m_solver.energy().value(guess))) guess = q;
  }
  const NewtonResult result = m_solver.solve(t1, guess);
  if (!result.converged) return result;
  m_previous = q;
  m_has_previous = true;
  q = guess;
  v.setZero();
  return result;
}

NewtonResult StaticLoadStepper::resolve(double t, VectorXd& q, VectorXd& v,
                                        const VectorXd& contact_reference) {
  VectorXd guess = q;
  if (m_problem.has_obstacles() && contact_reference.size() == q.size())
    m_solver.set_contact_reference(contact_reference);
  const NewtonResult result = m_solver.solve(t, guess);
  if (!result.converged) return result;
  q = guess;
  v.setZero();
  m_has_previous = false;  // no extrapolation from a state of another mesh
  return result;
}

std::unique_ptr<TimeStepper> make_static_load_stepper(const Problem& problem,
                                                      const SolverSettings& settings) {
  return std::make_unique<StaticLoadStepper>(problem, settings);
}

}  // namespace strata
