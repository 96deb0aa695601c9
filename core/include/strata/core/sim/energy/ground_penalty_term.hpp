#pragma once
/// \file ground_penalty_term.hpp
/// Frictionless penalty of a ground half-space, Φ(q) = ½ k Σ_i max(0, −n̂·(q_i − p))²
/// (ground_contact.hpp), on every DOF vertex.
#include "strata/core/sim/energy/energy_term.hpp"
#include "strata/core/sim/ground_contact.hpp"

namespace strata {

class GroundPenaltyTerm final : public EnergyTerm {
 public:
  /// `stiffness` k [N/m] > 0.
  GroundPenaltyTerm(const GroundPlane& ground, double stiffness)
      : m_ground(ground), m_stiffness(stiffness) {}
  std::string_view name() const override { return "ground_penalty"; }
  double value(ConstRef<VectorXd> q) const override;
  void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const override;
  /// k n̂n̂ᵀ per penetrating vertex: PSD, so exact and projected coincide.
  void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const override;

 private:
  GroundPlane m_ground;
  double m_stiffness;
};

}  // namespace strata
