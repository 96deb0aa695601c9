#pragma once
/// \file refinement_controller.hpp
/// Decides and applies changes of the active cut from a refinement indicator
/// (refinement_indicator.hpp), with hysteresis so that nodes do not flicker.
///
/// Rules of `decide` (η from the indicator, per active tet):
/// - refine an active node n when η_n > refine_threshold, its level is below max_level, at least
///   min_steps_between_changes steps have passed since n last changed, and the driver's veto
///   `may_refine(n)` (if set) allows it. With a budget of active elements, the largest η are
///   refined first and refinement stops before the cut would exceed the budget (+7 per node, −7
///   per merge kept).
/// - coarsen a parent p whose eight children are all active when (a) every child has
///   η_k < coarsen_indicator_fraction · refine_threshold (none of them wants refinement, with a
///   margin), (b) the children's stresses agree:
///       max_k ‖σ_k − σ̄‖_F / (‖σ̄‖_F + stress_floor · E) < coarsen_tolerance,   σ̄ = mean of σ_k,
///   (c) p has not changed for min_steps_between_changes steps, (d) the driver's veto
///   `may_coarsen(p)` (if set) allows it, and (e) with `balance`, the cut stays 2:1 balanced (no
///   active tet touching p's children, or planned to be refined next to them, is finer than p's
///   children), and (f) the driver's merge filter (if set) keeps p among the merges (a) – (e)
///   allow.
/// - no node is both refined and coarsened in one decision: a refined node's parent is never
///   coarsened (its η exceeds the coarsening bound).
///
/// Hysteresis, in two measures: the indicator must fall from above refine_threshold to below
/// coarsen_indicator_fraction · refine_threshold before siblings may merge, and the merge also
/// needs agreeing stresses (coarsen_tolerance ≪ 1); plus a minimum number of driver steps between
/// two changes of one node (refinement of n and coarsening back into n both count as changes of
/// n). Per-node records are arrays indexed by node id, grown with the tree's pool; a node's
/// record starts when its parent's refinement makes it active (so ids the tree released and
/// reused carry no stale history).
///
/// Lifecycle per adaptive step: the driver flattens the cut and fills a CutState → `decide` →
/// transfer state / `apply` → rebuild constraints and flatten. `apply` coarsens without
/// releasing tree nodes (release them after transferring state, TetTree::coarsen_subtree).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/refinement_indicator.hpp"

namespace strata {

/// Settings of the controller (defaults in brackets; why in the README, "Refinement criteria").
struct RefinementSettings {
  /// Refine where η exceeds this [3]: the force indicator gives η ≤ 1 for any uniform stress
  /// field, so 3 means "three times the body's typical force density".
  double refine_threshold = 3.0;
  /// Siblings may merge only when all their η are below this fraction of refine_threshold [0.5].
  double coarsen_indicator_fraction = 0.5;
  /// Largest relative spread of the siblings' stresses that still merges them [0.1].
  double coarsen_tolerance = 0.1;
  /// Stress floor relative to Young's modulus [1e-6]: stresses below stress_floor · E count as
  /// zero (used by the coarsening spread and by the default indicator).
  double stress_floor = 1e-6;
  /// Minimum driver steps between two changes of one node [10].
  long min_steps_between_changes = 10;
  /// Budget of active tets; 0 = none [0].
  Index max_active_elements = 0;
  /// Deepest level refinement may reach; −1 = the tree's max level [−1]. Capped by the tree's.
  int max_level = -1;
  /// Keep the cut 2:1 balanced (cut_balance.hpp) [false]. Balance refinements ignore the veto
  /// and the budget (they never create a level finer than one already active).
  bool balance = false;
};

/// Throws InputError naming `where` (e.g. "hierarchy.criteria") and the key unless thresholds
/// are positive and finite, coarsen_indicator_fraction ∈ (0, 1], coarsen_tolerance > 0,
/// stress_floor > 0, min_steps_between_changes ≥ 0, max_active_elements ≥ 0, max_level ≥ −1.
void validate_refinement_settings(const RefinementSettings& settings, const std::string& where);

/// The outcome of `decide`.
struct CutChanges {
  std::vector<NodeId> refine;   ///< active nodes to refine, largest η first
  std::vector<NodeId> coarsen;  ///< parents whose eight active children merge, ascending id
  VectorXd eta;                 ///< #T of the state: the indicator per flat tet
  Index over_threshold = 0;     ///< tets with η > refine_threshold
  Index refused = 0;            ///< of those, not refined (max level, veto, min steps or budget)
};

/// What `apply` did.
struct CutChangeCounts {
  Index refined = 0;          ///< nodes refined as decided
  Index coarsened = 0;        ///< parents coarsened
  Index balance_refined = 0;  ///< extra refinements made by 2:1 balancing
};

class RefinementController {
 public:
  /// Never changed (the initial per-node record).
  static constexpr long kNever = -(1L << 62);

  /// `indicator` defaults to ForceIndicator(settings.stress_floor). Validates the settings.
  explicit RefinementController(const RefinementSettings& settings = {},
                                std::unique_ptr<RefinementIndicator> indicator = nullptr);

  const RefinementSettings& settings() const { return m_settings; }
  const RefinementIndicator& indicator() const { return *m_indicator; }

  /// The driver's veto: refinement of n is considered only if may_refine(n) (e.g. false below an
  /// explicit integrator's stable-step limit, or for nodes touching fixed regions). Empty: all.
  void set_refinement_veto(std::function<bool(NodeId)> may_refine);
  /// The driver's veto on merging: the eight children of `parent` are merged only if
  /// may_coarsen(parent) (e.g. false for nodes touching fixed or prescribed regions, to keep them
  /// exact at the level they were refined to). Empty: all.
  void set_coarsening_veto(std::function<bool(NodeId)> may_coarsen);
  /// The driver's choice among the merges the rules allow (ascending parent ids in, a subset in
  /// ascending order out), made before the refinements are fitted to max_active_elements (e.g. a
  /// budget on an error estimate). Empty: all.
  using MergeFilter =
      std::function<std::vector<NodeId>(const CutState&, const std::vector<NodeId>&)>;
  void set_merge_filter(MergeFilter filter);

  /// The changes the criteria ask for on `cut` (whose flattening is `state.flat`), at
  /// `state.step`. Does not modify anything.
  CutChanges decide(const CutState& state, const ActiveCut& cut) const;

  /// Applies `changes` to `cut` (coarsenings first, then refinements, then balancing if enabled),
  /// recording `step` as the last change of every node refined or coarsened into. Entries no
  /// longer valid (node not active, parent not coarsenable) are skipped.
  CutChangeCounts apply(ActiveCut& cut, const CutChanges& changes, long step);

  /// Step of the last change of node n, or kNever.
  long last_change_step(NodeId n) const;
  /// Number of changes recorded for node n.
  int change_count(NodeId n) const;

 private:
  void record_change(NodeId n, long step);
  /// A refinement starts fresh records for the children (their ids may have been released and
  /// reused since they were last active).
  void reset_children(const TetTree& tree, NodeId n);

  RefinementSettings m_settings;
  std::unique_ptr<RefinementIndicator> m_indicator;
  std::function<bool(NodeId)> m_may_refine;
  std::function<bool(NodeId)> m_may_coarsen;
  MergeFilter m_merge_filter;
  std::vector<long> m_last_change;  ///< per node id
  std::vector<int> m_change_count;  ///< per node id
};

}  // namespace strata
