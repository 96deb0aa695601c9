#include "strata/core/sim/energy/external_work_term.hpp"

namespace strata {

void ExternalWorkTerm::add_gradient(ConstRef<VectorXd>, VectorXd& gradient) const {
  gradient -= m_scale * *m_forces;
}

}  // namespace strata
