#include "strata/core/sim/static_solver.hpp"

#include <algorithm>

#include "strata/core/sim/energy/elastic_term.hpp"
#include "strata/core/sim/energy/ground_penalty_term.hpp"
#include "strata/core/sim/energy/spring_term.hpp"

namespace strata {

StaticSolver::StaticSolver(const Problem& problem, LinearSolverKind solver, NewtonControls controls)
    : m_problem(problem),
      m_solver(solver),
      m_reduction(problem.model.stiffness_pattern(), problem.constrained),
      m_controls(controls),
      m_energy(problem.model.stiffness_pattern()) {
  problem.use_nested_spaces(m_solver, m_reduction.free_dofs());
  m_energy.emplace<ElasticTerm>(problem.model);
  if (problem.springs != nullptr) m_energy.emplace<SpringTerm>(problem.springs->springs());
  if (problem.has_obstacles())
    m_contact = &m_energy.emplace<ContactTerm>(*problem.obstacles, *problem.contact_points,
                                               problem.contact);
  m_external = &m_energy.emplace<ExternalWorkTerm>(problem.external_forces);
  if (problem.ground != nullptr)
    m_energy.emplace<GroundPenaltyTerm>(*problem.ground, problem.ground_stiffness);
}

NewtonResult StaticSolver::solve(double load_factor, VectorXd& q) {
  const double lambda = load_factor;
  const EmbeddedElasticModel& model = m_problem.model;
  m_external->set_load_factor(lambda);
  if (m_problem.has_timed_forces()) {
    m_problem.external_forces_at(lambda, lambda, m_timed_external);
    m_external->set_forces(m_timed_external);
    m_external->set_load_factor(1.0);
  }

  VectorXd unused_velocity = VectorXd::Zero(q.size());
  apply_dirichlet(m_problem.groups, model.rest_positions(), lambda, lambda, 0.0, q,
                  unused_velocity);
  if (m_contact != nullptr) {
    m_contact->set_step(m_contact_reference.size() == q.size() ? m_contact_reference : q, 0.0, 0.0);
    m_contact_reference.resize(0);
  }

  VectorXd f_int;
  model.forces(q, f_int);
  // The external forces at λ are s_f · f_ext.
  const bool timed = m_problem.has_timed_forces();
  const VectorXd& f_ext = timed ? m_timed_external : m_problem.external_forces;
  const double s_f = timed ? 1.0 : lambda;
  NewtonSettings settings;
  settings.max_iterations = m_controls.max_iterations;
  settings.tolerance = m_controls.tolerance;
  settings.exact_hessian = m_controls.exact_hessian;
  settings.force_scale = std::max((s_f * f_ext).norm(), f_int.norm());
  settings.residual_floor = internal_force_roundoff(model);
  const VectorXd& rest = model.rest_positions();
  const double size =
      (unflatten(rest).colwise().maxCoeff() - unflatten(rest).colwise().minCoeff()).norm();
  settings.step_tolerance = 1e-14 * size;
  settings.rest_positions = &rest;
  const LameParameters lame = model.material().lame();
  settings.energy_scale =
      (2 * lame.mu + lame.lambda) * model.total_rest_volume() + std::abs(s_f * f_ext.dot(q));
  return newton_minimize(m_energy, m_reduction, m_solver, settings, q, &m_workspace);
}

}  // namespace strata
