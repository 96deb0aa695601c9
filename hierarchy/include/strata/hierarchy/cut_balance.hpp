#pragma once
/// \file cut_balance.hpp
/// 2:1 balance of an active cut.
///
/// Definition used here: for every hanging vertex v (hanging_constraints.hpp) and every active tet
/// having v as a corner, that tet is at most one level finer than the coarsest active tet v hangs
/// on. This implies face- and edge-neighbour balance (active tets whose closures share a triangle
/// or a segment differ by at most one level: a corner of the finer one then hangs on the coarser
/// one), and in a balanced cut every hanging vertex is the midpoint of an edge of its host, with
/// chains only through vertices that hang on tets coarser still.
///
/// Balance is optional: HangingConstraints handles any valid cut. `balance_cut` enforces it by
/// refining the coarse side of each violation, repeating until none is left (each pass flattens
/// the cut: O(#active) per pass, passes ≤ the number of levels involved).
#include <vector>

#include "strata/hierarchy/active_cut.hpp"

namespace strata {

/// One violation of 2:1 balance.
struct BalanceViolation {
  int tree_vertex = -1;   ///< the hanging vertex (tree id)
  NodeId host = kNoNode;  ///< coarsest active tet it hangs on
  int host_level = -1;
  NodeId fine_node = kNoNode;  ///< finest active tet having it as a corner
  int fine_level = -1;         ///< > host_level + 1
};

/// All violations of the cut (one per offending hanging vertex).
std::vector<BalanceViolation> balance_violations(const ActiveCut& cut);

/// Whether `balance_violations(cut)` is empty.
bool is_balanced(const ActiveCut& cut);

/// Refines the hosts of violations until the cut is 2:1 balanced; returns the number of nodes
/// refined. The cut stays valid throughout.
Index balance_cut(ActiveCut& cut);

/// `cut.refine(n)` followed by `balance_cut(cut)`; returns the first child of `n`.
NodeId refine_balanced(ActiveCut& cut, NodeId n);

}  // namespace strata
