#pragma once
/// \file external_work_term.hpp
/// Potential of dead loads scaled by a load factor, E(q) = −s f_extᵀ q (gravity, region loads;
/// s is the static load factor, 1 in dynamic runs).
#include "strata/core/sim/energy/energy_term.hpp"

namespace strata {

class ExternalWorkTerm final : public EnergyTerm {
 public:
  /// `forces`: 3·#Q [N]; must outlive the term.
  explicit ExternalWorkTerm(const VectorXd& forces) : m_forces(&forces) {}
  /// Rebinds the term to another force vector (3·#Q, must outlive the term).
  void set_forces(const VectorXd& forces) { m_forces = &forces; }
  void set_load_factor(double s) { m_scale = s; }
  double load_factor() const { return m_scale; }
  std::string_view name() const override { return "external_work"; }
  double value(ConstRef<VectorXd> q) const override { return -m_scale * m_forces->dot(q); }
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  /// Linear in q: adds nothing.
  void add_hessian(ConstRef<VectorXd>, SparseMatrixd&, bool) const override {}

 private:
  const VectorXd* m_forces;
  double m_scale = 1.0;
};

}  // namespace strata
