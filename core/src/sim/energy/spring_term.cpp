#include "strata/core/sim/energy/spring_term.hpp"

namespace strata {

void SpringTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  VectorXd forces = VectorXd::Zero(gradient.size());
  m_springs.add_forces(q, forces);
  gradient -= forces;
}

}  // namespace strata
