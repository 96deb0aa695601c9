#pragma once
/// \file elastic_term.hpp
/// Elastic energy Ψ(P q) of the (embedded) tet mesh: the hyperelastic material of every element.
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/energy/energy_term.hpp"

namespace strata {

class ElasticTerm final : public EnergyTerm {
 public:
  /// `model` must outlive the term.
  explicit ElasticTerm(const EmbeddedElasticModel& model) : m_model(model) {}
  std::string_view name() const override { return "elastic"; }
  double value(ConstRef<VectorXd> q) const override;
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  /// Element Hessians ∂²ψ/∂F², PSD-projected per element when asked (isotropic_hessian.hpp).
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;
  /// The model assembles into H directly (its pattern is the Problem's).
  bool set_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;

 private:
  const EmbeddedElasticModel& m_model;
  mutable VectorXd m_forces;
  mutable SparseMatrixd m_stiffness;
};

}  // namespace strata
