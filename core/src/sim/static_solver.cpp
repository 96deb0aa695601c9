#include "strata/core/sim/static_solver.hpp"

#include <algorithm>

namespace strata {

StaticSolver::StaticSolver(const EmbeddedElasticModel& model, const VectorXd& external_forces,
                           const std::vector<DirichletGroup>& groups,
                           const std::vector<char>& constrained,
                           const std::optional<GroundPlane>& ground, double ground_stiffness,
                           LinearSolverKind solver, int max_newton_iterations,
                           double newton_tolerance)
    : m_model(model),
      m_external_forces(external_forces),
      m_groups(groups),
      m_ground(ground),
      m_ground_stiffness(ground_stiffness),
      m_solver(solver),
      m_reduction(model.stiffness_pattern(), constrained),
      m_max_iterations(max_newton_iterations),
      m_tolerance(newton_tolerance) {}

double StaticSolver::potential(double load_factor, const VectorXd& x) const {
  double e = m_model.energy(x) - load_factor * m_external_forces.dot(x);
  if (m_ground) e += ground_penalty_energy(*m_ground, m_ground_stiffness, x);
  return e;
}

VectorXd StaticSolver::contact_forces(const VectorXd& x) const {
  VectorXd gradient = VectorXd::Zero(x.size());
  if (m_ground) add_ground_penalty_gradient(*m_ground, m_ground_stiffness, x, gradient);
  return -gradient;
}

NewtonResult StaticSolver::solve(double load_factor, VectorXd& x) {
  const double lambda = load_factor;
  auto energy = [&](const VectorXd& y) { return potential(lambda, y); };
  auto gradient = [&](const VectorXd& y, VectorXd& g) {
    VectorXd f_int;
    m_model.forces(y, f_int);
    g = -f_int - lambda * m_external_forces;
    if (m_ground) add_ground_penalty_gradient(*m_ground, m_ground_stiffness, y, g);
  };
  auto hessian = [&](const VectorXd& y, SparseMatrixd& H) {
    m_model.stiffness(y, H, true);
    if (m_ground) add_ground_penalty_hessian(*m_ground, m_ground_stiffness, y, H);
  };

  VectorXd unused_velocity = VectorXd::Zero(x.size());
  apply_dirichlet(m_groups, m_model.rest_positions(), lambda, 0.0, x, unused_velocity);

  VectorXd f_int;
  m_model.forces(x, f_int);
  NewtonSettings settings;
  settings.max_iterations = m_max_iterations;
  settings.tolerance = m_tolerance;
  settings.force_scale = std::max((lambda * m_external_forces).norm(), f_int.norm());
  settings.residual_floor = internal_force_roundoff(m_model);
  const VectorXd& rest = m_model.rest_positions();
  const double size =
      (unflatten(rest).colwise().maxCoeff() - unflatten(rest).colwise().minCoeff()).norm();
  settings.step_tolerance = 1e-14 * size;
  const LameParameters lame = m_model.material().lame();
  settings.energy_scale = (2 * lame.mu + lame.lambda) * m_model.total_rest_volume() +
                          std::abs(lambda * m_external_forces.dot(x));
  return newton_minimize({energy, gradient, hessian}, m_reduction, m_solver, settings, x);
}

}  // namespace strata
