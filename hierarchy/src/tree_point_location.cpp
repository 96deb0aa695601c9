#include "strata/hierarchy/tree_point_location.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/red_refinement.hpp"

namespace strata {
namespace {

Eigen::Vector4d bey_barycentric(const TetTree& tree, NodeId n, const Vector3d& p) {
  const Matrix3x4d x = tree.bey_positions(n);
  return tet_barycentric_coordinates(p, x.col(0), x.col(1), x.col(2), x.col(3));
}

// Child of a refined node containing the point with Bey-barycentric λ; λ becomes the child's.
NodeId step_down(const TetTree& tree, NodeId n, Eigen::Vector4d& lambda) {
  int best = 0;
  double best_min = -std::numeric_limits<double>::infinity();
  Eigen::Vector4d best_mu = lambda;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector4d mu = bey_child_barycentric_map(k) * lambda;
    const double min_mu = mu.minCoeff();
    if (min_mu > best_min) {
      best = k;
      best_min = min_mu;
      best_mu = mu;
    }
  }
  lambda = best_mu;
  return tree.child(n, best);
}

// Final coordinates from the geometry of the node reached (accurate relative to its size), in
// the order of tet_vertices.
TreeLocation finish(const TetTree& tree, NodeId n, const Vector3d& p) {
  const Matrix3x4d x = tree.tet_positions(n);
  return {n, tet_barycentric_coordinates(p, x.col(0), x.col(1), x.col(2), x.col(3))};
}

MatrixX3d root_vertices(const TetTree& tree) {
  MatrixX3d vertices(tree.num_coarse_vertices(), 3);
  for (Index v = 0; v < vertices.rows(); ++v)
    vertices.row(v) = tree.vertex_position(static_cast<int>(v)).transpose();
  return vertices;
}

MatrixX4i root_tets(const TetTree& tree) {
  MatrixX4i tets(tree.num_roots(), 4);
  for (Index r = 0; r < tree.num_roots(); ++r) {
    const std::array<int, 4>& v = tree.bey_vertices(static_cast<NodeId>(r));
    tets.row(r) << v[0], v[1], v[2], v[3];
  }
  return tets;
}

}  // namespace

TreeLocation descend_to_point(const TetTree& tree, NodeId start, const Vector3d& p, int max_level) {
  STRATA_VERIFY(tree.is_alive(start), "descend_to_point: start node is not alive");
  NodeId n = start;
  Eigen::Vector4d lambda = bey_barycentric(tree, n, p);
  while (!tree.is_leaf(n) && (max_level == kDeepestLevel || tree.level(n) < max_level))
    n = step_down(tree, n, lambda);
  return finish(tree, n, p);
}

TreeLocation refine_to_point(TetTree& tree, NodeId start, const Vector3d& p, int level) {
  STRATA_VERIFY(tree.is_alive(start), "refine_to_point: start node is not alive");
  STRATA_VERIFY(level >= tree.level(start) && level <= tree.max_level(),
                "refine_to_point: level must be in level(start)..max_level");
  NodeId n = start;
  Eigen::Vector4d lambda = bey_barycentric(tree, n, p);
  while (tree.level(n) < level) {
    tree.refine(n);
    n = step_down(tree, n, lambda);
  }
  return finish(tree, n, p);
}

TreePointLocator::TreePointLocator(const TetTree& tree)
    : m_roots(root_vertices(tree), root_tets(tree)) {
  m_root_orientations.resize(tree.num_roots());
  for (Index r = 0; r < tree.num_roots(); ++r)
    m_root_orientations[r] = tree.node(static_cast<NodeId>(r)).orientation;
}

std::optional<TreeLocation> TreePointLocator::locate_root(const Vector3d& p,
                                                          double tolerance) const {
  const std::optional<TetLocation> found = m_roots.locate(p, tolerance);
  if (!found) return std::nullopt;
  // The grid holds the roots in Bey order; report coordinates in tet_vertices order.
  const auto root = static_cast<NodeId>(found->tet);
  Eigen::Vector4d barycentric = found->barycentric;
  if (m_root_orientations[root] < 0) std::swap(barycentric[2], barycentric[3]);
  return TreeLocation{root, barycentric};
}

std::optional<TreeLocation> TreePointLocator::locate(const TetTree& tree, const Vector3d& p,
                                                     double tolerance, int max_level) const {
  const std::optional<TetLocation> found = m_roots.locate(p, tolerance);
  if (!found) return std::nullopt;
  return descend_to_point(tree, static_cast<NodeId>(found->tet), p, max_level);
}

std::optional<TreeLocation> TreePointLocator::locate_and_refine(TetTree& tree, const Vector3d& p,
                                                                double tolerance, int level) const {
  const std::optional<TetLocation> found = m_roots.locate(p, tolerance);
  if (!found) return std::nullopt;
  return refine_to_point(tree, static_cast<NodeId>(found->tet), p, level);
}

}  // namespace strata
