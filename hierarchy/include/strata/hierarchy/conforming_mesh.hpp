#pragma once
/// \file conforming_mesh.hpp
/// An active cut as a conforming tet mesh, for tools that do not know hanging vertices: the
/// hanging vertices are resolved by closure refinement (red–green, as in Bey's and Bank's
/// closures).
///
/// An edge of an active tet is *marked* when its midpoint is a corner of some active tet (a finer
/// neighbour refined it). Closure: an active tet with a vertex two levels finer on an edge (a
/// marked edge whose halves are marked in turn) or inside a face (between the midpoints of a face
/// whose three edges are marked) is red-refined in the cut, repeated until none is left. Then each
/// face is split by its marked edges alone — one: from the midpoint to the opposite corner; three:
/// its four red triangles; two: the corner triangle between them and the rest along a diagonal
/// chosen from the face's vertex ids — so both neighbours split a shared face alike, and every tet
/// is written as
///   - no marked edge:             itself;
///   - one marked edge ab (m):     the two halves (a, m, c, d), (m, b, c, d);
///   - the three edges of a face:  the face's four red triangles, each joined to the apex;
///   - any other pattern:          its split faces, each joined to the tet's centroid (a new
///                                 vertex, not a tree vertex).
/// The result tiles the cut's domain (the same volume and boundary) without a hanging vertex. The
/// green tets (halves, face splits, centroid cones) are less regular than red ones and lie only
/// next to a change of level.
#include <vector>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/active_cut.hpp"

namespace strata {

struct ConformingMesh {
  TetMesh mesh;                    ///< positively oriented, vertices in increasing tree vertex id
  std::vector<NodeId> nodes;       ///< #T: the active tree node each tet lies in
  std::vector<int> tree_vertices;  ///< #V: tree vertex of each mesh vertex (−1: a centroid)
  /// #T: 0 an active tet as it is, 1 a half, 2 a face split, 3 a centroid cone.
  VectorXi green;
  Index centres = 0;              ///< centroid vertices added
  Index closure_refinements = 0;  ///< nodes red-refined by the closure
};

/// Refines `cut` by the closure (above) and returns it as a conforming mesh.
ConformingMesh conforming_cut_mesh(ActiveCut& cut);

}  // namespace strata
