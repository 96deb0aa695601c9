#pragma once
/// \file cut_transfer.hpp
/// Carrying per-vertex state (positions, velocities: 3·#V vertex-major) from one flattened cut to
/// another after refine / coarsen, through the tree's vertex ids.
///
/// A vertex present in both meshes keeps its value; a vertex new to the target mesh (created by
/// refinement) gets ½(value_a + value_b) of its tree parents, resolved in order of vertex level —
/// exactly the value the source mesh's piecewise-linear field has there when the new vertex lies on
/// an edge of a source tet (always for red refinement of an active node, whose new vertices are its
/// edge midpoints and, one level down, midpoints of the children's edges).
///
/// Precondition: no tree vertex id was freed and reused between the two flattenings (ActiveCut's
/// `coarsen` keeps the tree nodes unless asked to release them; release only after transferring).
/// Afterwards q = constraints.restrict_to_free(x) gives the target's free DOFs; its hanging
/// vertices then follow x = C q (on coarsening this moves vertices that were free before onto their
/// constraint).
#include "strata/core/fem/plasticity.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

/// `source_values` (3·#V of `source`) carried to `target` (returns 3·#V of `target`). Both are
/// flattenings of cuts of `tree`. Throws std::logic_error if a target vertex is neither in the
/// source nor reachable through parents that are.
VectorXd transfer_vertex_values(const TetTree& tree, const FlatTreeMesh& source,
                                ConstRef<VectorXd> source_values, const FlatTreeMesh& target);

/// Per-tet plastic state (plasticity.hpp) carried from `source` to `target` through the tree nodes:
/// a node active in both keeps its state; a node below a source node (refinement) inherits its
/// ancestor's Fₚ and ε̄ₚ (plastic deformation is uniform over a linear tet); a node above source
/// nodes (coarsening) gets their rest-volume-weighted mean of ε̄ₚ and of Fₚ⁻¹, the latter scaled to
/// det 1. `max_merge_change`, if given, receives the largest |ε̄ₚ(child) − ε̄ₚ(merged parent)|
/// (0 without merges). Throws std::logic_error if a target node is related to no source node.
PlasticState transfer_plastic_state(const TetTree& tree, const FlatTreeMesh& source,
                                    const PlasticState& source_state, const FlatTreeMesh& target,
                                    double* max_merge_change = nullptr);

}  // namespace strata
