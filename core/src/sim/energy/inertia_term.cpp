#include "strata/core/sim/energy/inertia_term.hpp"

#include "strata/core/common/error.hpp"

namespace strata {

void InertiaTerm::set_step(ConstRef<VectorXd> predicted, double h) {
  STRATA_VERIFY(predicted.size() == m_mass.size() && h > 0.0, "InertiaTerm::set_step: bad step");
  m_predicted = predicted;
  m_inverse_h2 = 1.0 / (h * h);
}

double InertiaTerm::value(ConstRef<VectorXd> q) const {
  const VectorXd dq = q - m_predicted;
  return 0.5 * m_inverse_h2 * dq.dot(m_mass.cwiseProduct(dq));
}

void InertiaTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  gradient += m_mass.cwiseProduct(q - m_predicted) * m_inverse_h2;
}

void InertiaTerm::add_hessian(ConstRef<VectorXd>, SparseMatrixd& hessian, bool) const {
  m_diagonal.add(m_inverse_h2, m_mass, hessian);
}

}  // namespace strata
