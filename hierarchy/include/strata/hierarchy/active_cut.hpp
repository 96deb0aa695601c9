#pragma once
/// \file active_cut.hpp
/// The active cut: the set of tree nodes the solver runs on. A valid cut contains, on every path
/// from a root down to a leaf of the TetTree, exactly one node — the active tets tile the coarse
/// mesh's domain without overlap. The tree may hold nodes below the cut (kept for re-refinement);
/// only the active ones are simulated.
///
/// Lifecycle (see tet_tree.hpp): mark → `refine` / `coarsen` here (the tree grows on demand) →
/// optionally `balance_cut` (cut_balance.hpp) → `flatten_nodes(tree, cut.nodes())` and
/// `HangingConstraints` (hanging_constraints.hpp) → simulate on x = C q.
///
/// Balance: the cut itself does not require 2:1 balance; hanging-vertex constraints resolve
/// chains of any depth. `balance_cut` enforces 2:1 balance when wanted (better conditioned, every
/// hanging vertex on an edge of a tet one level coarser).
///
/// Costs: membership is an array indexed by node id (O(1)); `nodes()` is unordered (refine and
/// coarsen swap-remove), `sorted_nodes()` gives a canonical order. Validation is
/// O(#active · depth). Holds a pointer to the tree: the tree must outlive the cut, and the tree
/// must not be coarsened below active nodes behind the cut's back (checked by `validate`).
#include <cstdint>
#include <vector>

#include "strata/hierarchy/tet_tree.hpp"

namespace strata {

class ActiveCut {
 public:
  /// The roots of `tree` (the coarse mesh).
  explicit ActiveCut(TetTree& tree);

  /// The given nodes. Throws InputError naming the offending node unless they form a valid cut
  /// (see `validate`).
  ActiveCut(TetTree& tree, const std::vector<NodeId>& nodes);

  /// Every node at `level`: refines the tree as needed (nodes below `level` already present are
  /// kept in the tree but inactive). Throws InputError if level ∉ 0..tree.max_level().
  static ActiveCut uniform(TetTree& tree, int level);

  // --- queries ---------------------------------------------------------------------------------
  const TetTree& tree() const { return *m_tree; }
  TetTree& tree() { return *m_tree; }
  /// Active nodes, unordered (#active).
  const std::vector<NodeId>& nodes() const { return m_nodes; }
  /// Active nodes in ascending id.
  std::vector<NodeId> sorted_nodes() const;
  /// Active nodes in depth-first order of the tree, root by root and child by child (for a
  /// uniform cut, the order of `uniform`): nodes near each other in space are mostly near each
  /// other in the list, whatever order the cut was edited in.
  std::vector<NodeId> depth_first_nodes() const;
  Index size() const { return static_cast<Index>(m_nodes.size()); }
  bool is_active(NodeId n) const;
  /// Deepest / shallowest level among the active nodes.
  int finest_level() const;
  int coarsest_level() const;
  /// Number of active nodes per level, levels 0..tree().max_level().
  std::vector<Index> level_counts() const;

  // --- editing ---------------------------------------------------------------------------------
  /// Replaces the active node `n` by its eight children (creating them in the tree if needed);
  /// returns the first child. Checked (std::logic_error): `n` active and below the max level.
  NodeId refine(NodeId n);
  /// Whether all eight children of `parent` are active.
  bool can_coarsen(NodeId parent) const;
  /// Replaces the eight active children of `parent` by `parent`. With `release_nodes`, the
  /// children are also released from the tree (TetTree::coarsen_subtree), freeing their block
  /// and midpoints no other node uses; otherwise they stay in the tree, inactive.
  /// Checked (std::logic_error): `can_coarsen(parent)`.
  void coarsen(NodeId parent, bool release_nodes = false);

  /// Throws InputError unless the active nodes form a valid cut: every node alive and listed once,
  /// no active node has an active ancestor, and the active nodes of each root cover it exactly
  /// (Σ 8^−level over its active descendants = 1, counted in exact integers). O(#active · depth).
  void validate() const;

 private:
  void activate(NodeId n);
  void deactivate(NodeId n);

  TetTree* m_tree;
  std::vector<NodeId> m_nodes;
  /// Index of a node in m_nodes, or −1 (indexed by node id; grows with the pool).
  std::vector<int> m_slot;
};

}  // namespace strata
