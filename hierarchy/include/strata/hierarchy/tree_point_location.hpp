#pragma once
/// \file tree_point_location.hpp
/// Point location through the refinement tree: find the root containing a point (grid locator over
/// the coarse mesh, point_location.hpp), then descend. The descent needs no geometry: with λ the
/// point's barycentric coordinates in a Bey-ordered node, its coordinates in child k are
/// μ = M_k λ (`bey_child_barycentric_map`, integer matrices); the child with the largest min μ
/// contains the point (all μ ≥ 0), or is the nearest guess for points slightly outside.
#include <cstdint>
#include <optional>
#include <vector>

#include "strata/core/mesh/point_location.hpp"
#include "strata/hierarchy/tet_tree.hpp"

namespace strata {

/// "As deep as the tree goes" for the `max_level` arguments below.
inline constexpr int kDeepestLevel = -1;

/// A point's place in the tree.
struct TreeLocation {
  NodeId node = kNoNode;        ///< the node reached
  Eigen::Vector4d barycentric;  ///< coordinates w.r.t. tree.tet_vertices(node): Σλ = 1, Σλx = p
};

/// Descends from the live node `start` towards `p` through existing nodes, stopping at a leaf or
/// at `max_level` (kDeepestLevel: no limit). `p` should lie in `start` (else the result is the
/// descendant nearest in barycentric terms, with some λ < 0).
TreeLocation descend_to_point(const TetTree& tree, NodeId start, const Vector3d& p,
                              int max_level = kDeepestLevel);

/// Like `descend_to_point` down to exactly `level` (≤ tree.max_level()), refining the nodes on the
/// way that have no children yet.
TreeLocation refine_to_point(TetTree& tree, NodeId start, const Vector3d& p, int level);

/// Point location in a whole tree. Holds a grid over the roots only (roots never change), so one
/// locator serves the tree through any refinement and coarsening.
class TreePointLocator {
 public:
  explicit TreePointLocator(const TetTree& tree);

  /// The root containing `p` (or nearest within `tolerance` [m]), as in TetLocator::locate; the
  /// barycentric coordinates are w.r.t. tree.tet_vertices(root).
  std::optional<TreeLocation> locate_root(const Vector3d& p, double tolerance) const;

  /// The deepest existing node (or the one at `max_level`) containing `p`; nothing if no root is
  /// within `tolerance`.
  std::optional<TreeLocation> locate(const TetTree& tree, const Vector3d& p, double tolerance,
                                     int max_level = kDeepestLevel) const;

  /// The node at `level` containing `p`, refining lazily on the way down.
  std::optional<TreeLocation> locate_and_refine(TetTree& tree, const Vector3d& p, double tolerance,
                                                int level) const;

 private:
  TetLocator m_roots;                            ///< grid over the roots in Bey order
  std::vector<std::int8_t> m_root_orientations;  ///< TetNode::orientation per root
};

}  // namespace strata
