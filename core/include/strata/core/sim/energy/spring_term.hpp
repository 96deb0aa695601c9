#pragma once
/// \file spring_term.hpp
/// Energy of the surface springs (surface_springs.hpp) on the DOFs of a mesh without an
/// embedding (q = x).
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/surface_springs.hpp"

namespace strata {

class SpringTerm final : public EnergyTerm {
 public:
  /// `springs` must outlive the term.
  explicit SpringTerm(const SurfaceSprings& springs) : m_springs(springs) {}
  std::string_view name() const override { return "surface_springs"; }
  double value(ConstRef<VectorXd> q) const override { return m_springs.energy(q); }
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override {
    m_springs.add_hessian(q, hessian, project_psd);
  }

 private:
  const SurfaceSprings& m_springs;
};

}  // namespace strata
