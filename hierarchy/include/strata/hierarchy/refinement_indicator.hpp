#pragma once
/// \file refinement_indicator.hpp
/// The pluggable refinement indicator: one dimensionless number η_t ≥ 0 per active tet of a cut,
/// large where the tet should be refined. The controller (refinement_controller.hpp) refines
/// where η exceeds its threshold and coarsens siblings whose η are small and whose stresses agree.
/// Shipped: ForceIndicator (refinement_force_indicator.hpp, the default) and
/// StressJumpIndicator (refinement_stress_jump_indicator.hpp, for comparison).
///
/// Also the stress measures shared by the indicators and the controller's coarsening test.
#include <array>
#include <string>

#include "strata/core/common/types.hpp"
#include "strata/hierarchy/cut_state.hpp"

namespace strata {

/// Interface of a refinement criterion. `evaluate` is const and safe to call concurrently on
/// different states (implementations keep at most internally guarded caches).
class RefinementIndicator {
 public:
  virtual ~RefinementIndicator() = default;
  /// Short name for logs and stats ("force", "stress_jump").
  virtual std::string name() const = 0;
  /// η per flat tet of `state` (resized to #T, dimensionless, ≥ 0).
  virtual void evaluate(const CutState& state, VectorXd& eta) const = 0;
  /// The indicator the parent (at `parent_level`) of the eight sibling flat tets `children`
  /// would have after they merge, in η's units; +∞ when the indicator cannot tell (then the
  /// controller merges only siblings whose stresses agree).
  virtual double merge_indicator(const CutState& state, const std::array<int, 8>& children,
                                 int parent_level) const;
};

/// Frobenius norm ‖σ‖_F of a symmetric tensor in Voigt form [xx yy zz xy yz xz]
/// (off-diagonal entries count twice).
double voigt_frobenius_norm(const Vector6d& voigt);

/// ‖σ_t‖_F per row of a #T × 6 Voigt array [Pa].
VectorXd tet_stress_norms(const Eigen::Matrix<double, Eigen::Dynamic, 6>& cauchy_stress);

/// Rest volume of each tet of `mesh` (#T) [m³].
VectorXd tet_rest_volumes(const TetMesh& mesh);

/// Volume-weighted RMS stress of a cut, S_σ = √(Σ_t V_t ‖σ_t‖_F² / Σ_t V_t) [Pa], with V_t the
/// rest volumes of `state.flat.mesh`: the body's typical stress level, independent of the cut.
double volume_rms_stress(const CutState& state);

}  // namespace strata
