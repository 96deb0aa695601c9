#include "strata/core/sim/energy/ground_penalty_term.hpp"

namespace strata {

double GroundPenaltyTerm::value(ConstRef<VectorXd> q) const {
  return ground_penalty_energy(m_ground, m_stiffness, q);
}

void GroundPenaltyTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  add_ground_penalty_gradient(m_ground, m_stiffness, q, gradient);
}

void GroundPenaltyTerm::add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool) const {
  add_ground_penalty_hessian(m_ground, m_stiffness, q, hessian);
}

}  // namespace strata
