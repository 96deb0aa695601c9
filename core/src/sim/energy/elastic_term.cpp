#include "strata/core/sim/energy/elastic_term.hpp"

namespace strata {

double ElasticTerm::value(ConstRef<VectorXd> q) const {
  return m_model.energy(q);
}

void ElasticTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  m_model.forces(q, m_forces);
  gradient -= m_forces;
}

void ElasticTerm::add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian,
                              bool project_psd) const {
  m_model.stiffness(q, m_stiffness, project_psd);
  add_values_same_pattern(m_stiffness, 1.0, hessian);
}

bool ElasticTerm::set_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian,
                              bool project_psd) const {
  m_model.stiffness(q, hessian, project_psd);
  return true;
}

}  // namespace strata
