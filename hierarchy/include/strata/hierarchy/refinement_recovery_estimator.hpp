#pragma once
/// \file refinement_recovery_estimator.hpp
/// A posteriori error estimate of a cut against full resolution by strain recovery (Zienkiewicz
/// & Zhu 1987): the piecewise-constant Green strain E_t of the active tets is averaged
/// (rest-volume weighted) onto the flat vertices, E*, and the energy of the difference,
///
///     η_t² = ∫_t 2 ψ(E* − E_t) dV,   ψ(e) = μ e:e + λ/2 tr(e)²,
///
/// (exact for the linear E* over the tet: ∫_t q(d) = V_t/20 (Σ_i q(d_i) + q(Σ_i d_i))) estimates
/// the squared energy-norm error of tet t against the exact solution. Against the tree's finest
/// level only the part refinement would remove counts, in the measure of displacements: with the
/// energy error of linear elements falling as h, a tet at level ℓ of a tree of depth L keeps the
/// amplitude 2^−(L−ℓ) of its error at the finest level; and a displacement error falls faster
/// than the energy error (by h in the asymptotic range, Aubin–Nitsche; less where linear tets
/// lock in bending). With the exponent ½ of h_ℓ / h_0 = 2^−ℓ, fitted on the project's scenes
/// (README, "Error control"; the full Aubin–Nitsche factor 2^−ℓ let a bending cantilever's cut
/// reach 14 % error at τ = 5 %),
///
///     η_t,full² = η_t² (1 − 2^−(L−ℓ_t))² 2^−ℓ_t,   z = C · √(Σ_t η_t,full² / ‖u‖_E²),
///
/// with ‖u‖_E² = Σ_t 2 V_t ψ(E_t) the solution's energy norm (or the largest over the run so far,
/// CutState::solution_energy_scale, as the true error is relative to the largest displacement of
/// the run) and C the calibration from the relative energy-norm error to the relative
/// displacement error (`kDisplacementPerEnergyError`). z is an upper estimate: on the project's
/// adaptive cuts it was 2–40 times the true error.
///
/// The lower one is the error of the load's work. Against the finest level the cut's energy error
/// is ‖u_L − u_c‖_E² = Σ_t η_t² (1 − 4^−(L−ℓ_t)) (Galerkin orthogonality: each level removes 3/4
/// of the error energy of linear elements), and for a linear problem it equals F·(u_L − u_c), the
/// error of the load's work. Relative to the work itself,
///
///     c = Σ_t η_t² (1 − 4^−(L−ℓ_t)) / ‖u‖_E²,
///
/// is the relative displacement error in the load's own direction, weighted by the load; the
/// largest probe error is mostly larger (c was 0.1–1.1 times it on the project's adaptive cuts).
/// The two bracket the error, c ≤ error ≤ z, on most measured cuts, up to 50 apart, and the
/// energy-norm estimate is their geometric mean √(z c) (for plastic materials z: the identity
/// behind c holds for elastic states only, and a plastic zone formed on a coarse cut stays in the
/// run's history).
///
/// Both are relative to the whole body's energy, which dilutes the error at a load much weaker
/// than the body's main one (a small patch beside a large one, a patch on a body sagging under
/// its own weight): its displacement error is large against the largest displacement, its energy
/// small against the body's. The local estimate measures that error where it is: a strain error
/// |E* − E_t| across a tet of size h_t (the edge of a regular tet of its volume) is a
/// displacement error of about h_t |E* − E_t|, and
///
///     e_loc = max_t δ_t / max |u|,   δ_t = (1 − 2^−(L−ℓ_t)) h_t max_i |E*_i − E_t|,
///
/// over the tet's vertices i, |·| the Frobenius norm, relative to the largest displacement (of
/// the run so far, CutState::solution_displacement_scale). It sees no error spread over the body
/// (bending of coarse tets, which √(z c) sees), and the estimate of the run is the larger of the
/// two,
///
///     e = max(√(z c), e_loc).
///
/// e is the estimated error of the run in the measure hierarchy.tolerance bounds. It is zero for
/// affine fields and uniform strain, grows with strain jumps between neighbours (bending on
/// coarse tets, concentrated loads), and is zero on the finest level. The effectivities of √(z c)
/// and of e on the project's scenes are in the README ("Error control", "Multiresolution runs:
/// measured").
///
/// As a refinement indicator the estimate is normalised by an equidistributed share of a
/// tolerance τ_z on z: η̂_t = √(N η_t,full² / ((τ_z/C)² ‖u‖_E²)), with N the number of active tets,
/// so η̂ > 1 marks the tets whose error exceeds their share (refine_threshold 1). The heuristic
/// τ_z = (τ² z² / c)^⅓ = z (τ/√(z c))^⅔ is z when √(z c) = τ (it would mean √(z c) ≤ τ exactly
/// if c fell as z² under refinement); then Σ_t η̂_t² = N (√(z c)/τ)^{4/3} (elastic, c > 0;
/// plastic: τ_z = τ and N (z/τ)²; c = 0: τ_z = ∞ and η̂ = 0). The coarsening test of the
/// children's η̂ uses the same normalisation; merge_indicator uses min(τ, τ_z), as a merge raises
/// c, which τ_z does not see. A tet whose local term exceeds the tolerance, δ_t > τ max|u|, is
/// marked as well: η_t = max(η̂_t, δ_t / (τ max|u|)).
#include <vector>

#include "strata/core/common/compressed_lists.hpp"
#include "strata/hierarchy/refinement_indicator.hpp"

namespace strata {

/// Relative displacement error per relative energy-norm error (calibration constant C).
inline constexpr double kDisplacementPerEnergyError = 1.0;

struct RecoveryEstimate {
  VectorXd element_error_sq;        ///< η_t,full² per flat tet [J] (energy norm², 2ψ·V)
  VectorXd element_raw_error_sq;    ///< η_t² per flat tet, against the exact solution [J]
  double solution_energy_sq = 0.0;  ///< ‖u‖_E² of this state [J]
  /// max(‖u‖_E², state.solution_energy_scale): what the relative errors are relative to [J].
  double reference_energy_sq = 0.0;
  /// The estimated relative displacement error against full resolution, e = max(√(z c), e_loc)
  /// above.
  double relative_error = 0.0;
  /// The upper estimate z above.
  double upper_error = 0.0;
  /// The relative error of the load's work against the finest level, c above.
  double load_work_error = 0.0;
  /// Plastic materials: e = z. The load-work identity holds for elastic states only, and a plastic
  /// zone formed on a coarse cut stays in the run's history.
  bool upper_only = false;
  /// √(Σ_t η_t² / ‖u‖_E²): the relative energy-norm error against the exact solution.
  double relative_energy_error = 0.0;
  /// The energy-norm estimate √(z c) (z for plastic materials) that relative_error takes the
  /// larger of with local_error; the refinement marking's share τ_z follows from it.
  double recovery_error = 0.0;
  /// δ_t = (1 − 2^−(L−ℓ_t)) h_t max_i |E*_i − E_t| per flat tet [m]: the displacement a strain
  /// error across the tet's size amounts to, the part refinement to the finest level removes
  /// (zero on the finest level, whose strain error the full-resolution run shares).
  VectorXd element_local_error;
  /// Per flat vertex v: the recovered strain E*_v (Voigt [xx yy zz xy yz xz]), the rest-volume
  /// weighted mean of its tets' Green strains, then the rest volume of those tets [m³].
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> recovered_strain;
  /// max(largest vertex displacement of this state, state.solution_displacement_scale) [m].
  double reference_displacement = 0.0;
  /// The local estimate e_loc = max_t δ_t / reference_displacement.
  double local_error = 0.0;
};

/// What the estimate reads of a flat cut's rest geometry, the same for every state on the cut: the
/// driver computes it once per cut and passes it in CutState::recovery_geometry.
struct RecoveryGeometry {
  VectorXd volume;           ///< #T signed rest volumes (tet_rest_volumes)
  VectorXd size;             ///< #T: (6√2 |V|)^⅓, the edge of a regular tet of that volume [m]
  CompressedLists incident;  ///< #V: the tets of each vertex, ascending
};

/// The rest geometry of `mesh` (parallel).
RecoveryGeometry recovery_geometry(const TetMesh& mesh);

/// The estimate of `state` (a tree of depth state.tree.max_level()). Uses
/// state.recovery_geometry when given (it must be of state.flat.mesh), computes it otherwise.
RecoveryEstimate recovery_error_estimate(const CutState& state);

/// The merges of one change that fit a budget on the estimate.
struct BudgetedMerges {
  std::vector<NodeId> kept;      ///< parents to merge, ascending id
  double predicted_error = 0.0;  ///< the estimate √(z c) predicted after those merges
};

/// The merges of `parents` (each a parent whose eight children are active tets of state.flat)
/// that keep the predicted energy-norm estimate √(z c) within `budget`, and the local term e_loc
/// too. A merge replaces the children's terms by the parent's, whose squared error is predicted
/// as the larger of 4 Σ_k η_k² (the error energy of linear elements rises by 4 per level
/// coarser) and Σ_k η_k² plus the energy the merge removes (RecoveryIndicator::merge_indicator);
/// z and c follow with the parent's level. The merges are visited in order of the estimate each
/// alone would leave, and each is kept if the predicted √(z c) with it and the merges kept
/// before stays within the budget. Every rise is ≥ 0, so a state whose estimate already exceeds
/// the budget keeps none. A state without deformation keeps every merge. For e_loc: while it
/// exceeds the budget nothing merges, and a merge whose parent's predicted δ exceeds half the
/// budget times max |u| is not made. That δ is its share times its size times the larger of its
/// own strain (of the linear field through its corners' current positions) against the
/// recovered strains at its corners, and its children's share-weighted strain error (zero on the
/// finest level) plus the largest deviation of a child's strain from their mean plus its own
/// strain's difference from that mean. `estimate` must be recovery_error_estimate(state).
BudgetedMerges merges_within_budget(const CutState& state, const RecoveryEstimate& estimate,
                                    const std::vector<NodeId>& parents, double budget);

class RecoveryIndicator final : public RefinementIndicator {
 public:
  /// `tolerance` τ ∈ (0, 1): the relative displacement error the run may have.
  explicit RecoveryIndicator(double tolerance);
  std::string name() const override { return "recovery"; }
  void evaluate(const CutState& state, VectorXd& eta) const override;
  /// The energy a merge removes, Σ_k 2 V_k ψ(E_k − Ē) over the children (Ē their
  /// volume-weighted mean Green strain), in the measure of the
  /// parent's level against the finest and normalised by the tet's share of the tolerance as η:
  /// siblings in a region of low strain merge even where their stresses differ relatively.
  double merge_indicator(const CutState& state, const std::array<int, 8>& children,
                         int parent_level) const override;

 private:
  double m_tolerance;
};

}  // namespace strata
