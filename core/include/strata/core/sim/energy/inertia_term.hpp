#pragma once
/// \file inertia_term.hpp
/// Inertia of one backward-Euler step, E(q) = 1/(2h²) ‖q − q̃‖²_M with q̃ = qₙ + h vₙ and M the
/// lumped (diagonal) mass: its stationarity with the other terms is M (v_{n+1} − vₙ)/h = f(q).
#include "strata/core/sim/energy/energy_term.hpp"

namespace strata {

class InertiaTerm final : public EnergyTerm {
 public:
  /// `dof_mass`: 3·#Q lumped masses [kg]; must outlive the term.
  explicit InertiaTerm(const VectorXd& dof_mass) : m_mass(dof_mass) {}
  /// Sets the step: predicted position q̃ (3·#Q) and step h > 0 [s].
  void set_step(ConstRef<VectorXd> predicted, double h);
  std::string_view name() const override { return "inertia"; }
  double value(ConstRef<VectorXd> q) const override;
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;

 private:
  const VectorXd& m_mass;
  VectorXd m_predicted;
  double m_inverse_h2 = 0.0;
  mutable DiagonalPositions m_diagonal;
};

}  // namespace strata
