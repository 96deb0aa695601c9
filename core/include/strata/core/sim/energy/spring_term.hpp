#pragma once
/// \file spring_term.hpp
/// Energy of a set of springs (spring_set.hpp: the surface springs, the skeleton-spring body) on
/// DOFs that are the springs' vertices (q = x).
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/spring_set.hpp"

namespace strata {

class SpringTerm final : public EnergyTerm {
 public:
  /// `springs` must outlive the term.
  explicit SpringTerm(const SpringSet& springs) : m_springs(springs) {}
  std::string_view name() const override { return "springs"; }
  double value(ConstRef<VectorXd> q) const override { return m_springs.energy(q); }
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override {
    m_springs.add_hessian(q, hessian, project_psd);
  }

 private:
  const SpringSet& m_springs;
};

}  // namespace strata
