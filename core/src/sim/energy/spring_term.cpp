#include "strata/core/sim/energy/spring_term.hpp"

namespace strata {

void SpringTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  m_springs.add_forces(q, gradient, -1.0);
}

}  // namespace strata
