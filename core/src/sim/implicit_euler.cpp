#include "strata/core/sim/implicit_euler.hpp"

#include "strata/core/sim/energy/elastic_term.hpp"
#include "strata/core/sim/energy/external_work_term.hpp"
#include "strata/core/sim/energy/spring_term.hpp"

#include <cmath>

namespace strata {

ImplicitEuler::ImplicitEuler(const Problem& problem, LinearSolverKind solver,
                             NewtonControls controls)
    : m_problem(problem),
      m_solver(solver),
      m_reduction(problem.model.stiffness_pattern(), problem.constrained),
      m_controls(controls),
      m_energy(problem.model.stiffness_pattern()) {
  problem.use_nested_spaces(m_solver, m_reduction.free_dofs());
  m_inertia = &m_energy.emplace<InertiaTerm>(problem.dof_mass);
  m_energy.emplace<ElasticTerm>(problem.model);
  if (problem.springs != nullptr) m_energy.emplace<SpringTerm>(problem.springs->springs());
  if (problem.has_obstacles())
    m_contact = &m_energy.emplace<ContactTerm>(*problem.obstacles, *problem.contact_points,
                                               problem.contact);
  m_external = &m_energy.emplace<ExternalWorkTerm>(problem.external_forces);
  if (problem.mass_damping > 0.0 || problem.stiffness_damping > 0.0)
    m_damping = &m_energy.emplace<RayleighDampingTerm>(
        problem.model, problem.dof_mass, problem.mass_damping, problem.stiffness_damping);
}

NewtonResult ImplicitEuler::step(double t, double h, VectorXd& x, VectorXd& v) {
  const Problem& sys = m_problem;
  const EmbeddedElasticModel& model = sys.model;
  const VectorXd& M = sys.dof_mass;
  const VectorXd x_start = x;
  const VectorXd x_tilde = x + h * v;
  m_inertia->set_step(x_tilde, h);
  if (m_damping != nullptr) m_damping->set_step(x_start, h);

  if (sys.has_timed_forces()) {
    sys.external_forces_at(t + h, 1.0, m_timed_external);
    m_external->set_forces(m_timed_external);
  }
  const VectorXd& f_ext = sys.has_timed_forces() ? m_timed_external : sys.external_forces;

  VectorXd y = x_tilde;
  VectorXd v_end = v;
  sys.apply_constraints(t + h, y, v_end);
  if (m_contact != nullptr) {
    m_contact->set_step(x_start, t, t + h);
    // Newton needs a start inside the barrier's domain: the start of the step if q̃ is not.
    if (!std::isfinite(m_contact->value(y))) {
      y = x_start;
      sys.apply_constraints(t + h, y, v_end);
      // An obstacle that moved into the body within the step: lift the start out of it.
      if (!std::isfinite(m_contact->value(y))) m_contact->push_out(y, sys.constrained, 0.5);
    }
  }

  VectorXd f_int;
  model.forces(y, f_int);
  NewtonSettings settings;
  settings.max_iterations = m_controls.max_iterations;
  settings.tolerance = m_controls.tolerance;
  settings.exact_hessian = m_controls.exact_hessian;
  settings.force_scale = M.cwiseProduct(y - x_tilde).norm() / (h * h) + f_int.norm() +
                         f_ext.norm() + M.cwiseProduct(v).norm() / h;
  settings.step_tolerance = 1e-13 * sys.diagonal;
  settings.residual_floor = internal_force_roundoff(model);
  settings.rest_positions = &model.rest_positions();
  const LameParameters lame = model.material().lame();
  settings.energy_scale = (2 * lame.mu + lame.lambda) * model.total_rest_volume() +
                          std::abs(f_ext.dot(y)) +
                          0.5 / (h * h) * (y - x_tilde).dot(M.cwiseProduct(y - x_tilde));

  const NewtonResult result =
      newton_minimize(m_energy, m_reduction, m_solver, settings, y, &m_workspace);
  v = (y - x_start) / h;
  x = y;
  // Dirichlet velocities are the prescribed ones, not the difference quotient.
  sys.apply_constraints(t + h, x, v);
  return result;
}

}  // namespace strata
