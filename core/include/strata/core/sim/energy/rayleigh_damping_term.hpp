#pragma once
/// \file rayleigh_damping_term.hpp
/// Rayleigh damping of one backward-Euler step as a potential,
///   E(q) = 1/(2h) (q − qₙ)ᵀ (α M + β Kₙ) (q − qₙ),
/// whose gradient is the damping force −(α M + β Kₙ) v_{n+1} with v_{n+1} = (q − qₙ)/h. The
/// stiffness Kₙ is lagged to the start of the step and PSD-projected, so E is convex.
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/energy/energy_term.hpp"

namespace strata {

class RayleighDampingTerm final : public EnergyTerm {
 public:
  /// α [1/s] ≥ 0 and β [s] ≥ 0; `model` and `dof_mass` must outlive the term.
  RayleighDampingTerm(const EmbeddedElasticModel& model, const VectorXd& dof_mass,
                      double mass_damping, double stiffness_damping);
  /// Sets the step: start position qₙ (Kₙ is assembled there when β > 0) and h > 0 [s].
  void set_step(ConstRef<VectorXd> start, double h);
  std::string_view name() const override { return "rayleigh_damping"; }
  double value(ConstRef<VectorXd> q) const override;
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  /// The term is quadratic with a PSD matrix: exact and projected Hessians coincide.
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;

 private:
  const EmbeddedElasticModel& m_model;
  const VectorXd& m_mass;
  double m_alpha;
  double m_beta;
  double m_h = 1.0;
  VectorXd m_start;
  SparseMatrixd m_start_stiffness;  ///< Kₙ (projected), the model's pattern
  mutable DiagonalPositions m_diagonal;
};

}  // namespace strata
