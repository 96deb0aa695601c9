#pragma once
/// \file uniform_refinement.hpp
/// Uniform red refinement: every root refined to the same level.
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/tet_tree.hpp"

namespace strata {

/// Refines every leaf of `tree` above `level` until all leaves are at `level` or deeper
/// (deeper leaves are kept). Checked: level ≤ tree.max_level(). Returns the nodes created.
Index refine_uniformly(TetTree& tree, int level);

/// One-shot: `mesh` red-refined `levels` times (8^levels · #T tets, conforming, positively
/// oriented, the coarse vertices first with their indices). Throws InputError for an invalid mesh
/// or levels outside 0..TetTree::kMaxSupportedLevel.
TetMesh uniform_refinement(const TetMesh& mesh, int levels);

}  // namespace strata
