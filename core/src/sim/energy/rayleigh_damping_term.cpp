#include "strata/core/sim/energy/rayleigh_damping_term.hpp"

#include "strata/core/common/error.hpp"

namespace strata {

RayleighDampingTerm::RayleighDampingTerm(const EmbeddedElasticModel& model,
                                         const VectorXd& dof_mass, double mass_damping,
                                         double stiffness_damping)
    : m_model(model), m_mass(dof_mass), m_alpha(mass_damping), m_beta(stiffness_damping) {
  STRATA_VERIFY(m_alpha >= 0.0 && m_beta >= 0.0, "RayleighDampingTerm: negative coefficient");
}

void RayleighDampingTerm::set_step(ConstRef<VectorXd> start, double h) {
  STRATA_VERIFY(start.size() == m_mass.size() && h > 0.0,
                "RayleighDampingTerm::set_step: bad step");
  m_start = start;
  m_h = h;
  if (m_beta > 0.0) m_model.stiffness(m_start, m_start_stiffness, true);
}

double RayleighDampingTerm::value(ConstRef<VectorXd> q) const {
  const VectorXd dq = q - m_start;
  double e = 0.5 * m_alpha / m_h * dq.dot(m_mass.cwiseProduct(dq));
  if (m_beta > 0.0) e += 0.5 * m_beta / m_h * dq.dot(m_start_stiffness * dq);
  return e;
}

void RayleighDampingTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  const VectorXd dq = q - m_start;
  gradient += (m_alpha / m_h) * m_mass.cwiseProduct(dq);
  if (m_beta > 0.0) gradient += (m_beta / m_h) * (m_start_stiffness * dq);
}

void RayleighDampingTerm::add_hessian(ConstRef<VectorXd>, SparseMatrixd& hessian, bool) const {
  if (m_alpha > 0.0) m_diagonal.add(m_alpha / m_h, m_mass, hessian);
  if (m_beta > 0.0) add_values_same_pattern(m_start_stiffness, m_beta / m_h, hessian);
}

}  // namespace strata
