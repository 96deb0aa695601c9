#pragma once
/// \file cut_levels.hpp
/// The refinement tree's levels below a flattened cut, as the nested spaces of the multigrid
/// solver (core/sim/multigrid.hpp).
///
/// Space k is the cut with every active tet finer than level k replaced by its level-k ancestor.
/// Its DOF vertices are the cut's free (non-hanging) vertices of tree vertex level ≤ k: a vertex
/// of level ≤ k stays a corner of the capped tets, and no capped tet has it as an edge midpoint
/// (that would make its level k + 1). Hanging vertices of level ≤ k hang in space k as in the cut.
/// Hence space k ⊂ space k+1 (P1 on nested tets, conforming through the same constraints), and
/// the prolongation is interpolation: a vertex of level ≤ k keeps its value; a vertex of level
/// k + 1 is the midpoint of two vertices a, b of level ≤ k (TetTree::vertex_parents) and takes
/// ½(x_a + x_b), where a hanging parent is expressed through the cut's constraint row C_a (which
/// involves only vertices of lower level).
///
/// Levels that would shrink the space by less than a factor 1/0.7 (a cut refined only locally) are
/// merged into the next finer one (their prolongations multiplied), so every coarse level pays
/// for itself.
///
/// Each coarse space's keys (NestedSpaces::keys) are its vertices' tree vertex ids: two cuts of
/// one tree whose coarse spaces have the same keys and prolongations have the same coarse levels,
/// which a cut change then carries over (MultigridPreconditioner::offer_coarse_levels). The tree
/// reuses the ids of vertices it releases, so keys compare only cuts whose vertices are all alive:
/// a cut change flattens the new cut before the merged subtrees are released.
#include "strata/core/sim/multigrid.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"

namespace strata {

/// Nested spaces of `cut` (flattened from `tree`): empty when every free vertex is a coarse
/// vertex (the cut is the coarse mesh). The finest space is the cut's free vertices in the order
/// of HangingConstraints::free_vertices.
NestedSpaces cut_nested_spaces(const TetTree& tree, const ConstrainedCut& cut);

}  // namespace strata
