#pragma once
/// \file triangle_bvh.hpp
/// A bounding-volume hierarchy over a triangle surface: closest-point queries and the generalized
/// winding number (Jacobson et al. 2013) with the far-field dipole approximation of Barill et al.,
/// "Fast Winding Numbers for Soups and Clouds" (SIGGRAPH 2018).
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

/// Closest point on the triangle (a, b, c) to `p` and its barycentric coordinates (sum 1, all ≥ 0;
/// Ericson, Real-Time Collision Detection, 5.1.5). Degenerate triangles are handled.
Vector3d closest_point_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                                   const Vector3d& c, Vector3d& barycentric);

/// Signed solid angle [sr] that the oriented triangle (a, b, c) subtends at `p` (Van Oosterom and
/// Strackee 1983): positive when `p` lies behind the triangle, i.e. (a−p)·((b−p)×(c−p)) > 0.
double triangle_solid_angle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                            const Vector3d& c);

/// Closest point on a surface.
struct SurfaceClosestPoint {
  Index triangle = -1;    ///< index of the triangle holding the closest point
  Vector3d point;         ///< the closest point [m]
  Vector3d barycentric;   ///< its coordinates in that triangle
  double distance = 0.0;  ///< |p − point| [m]
};

/// Static BVH over the triangles of a surface (#V × 3 vertices, #F × 3 triangles). Build
/// O(#F log #F); queries O(log #F) for well-spread input. Queries are const and thread-safe.
class TriangleBvh {
 public:
  /// Throws InputError if a triangle index is out of range. An empty surface is allowed (queries
  /// then return triangle −1 / winding number 0).
  TriangleBvh(ConstRef<MatrixX3d> vertices, ConstRef<MatrixX3i> triangles);

  /// Closest point on the surface to `p` (exact, with pruning by box distance).
  SurfaceClosestPoint closest_point(const Vector3d& p) const;

  /// Generalized winding number w(p) = Σ_f Ω_f(p) / 4π: 1 inside and 0 outside a closed
  /// outward-oriented surface, a smooth in-between value near holes of an open one. Clusters
  /// farther than `accuracy` × their radius use the dipole approximation (N·(c−p))/(4π|c−p|³)
  /// with N the summed area vectors and c the area-weighted centroid; accuracy ≤ 0 is exact.
  double winding_number(const Vector3d& p, double accuracy = 2.0) const;

  Index num_triangles() const { return m_triangles.rows(); }

 private:
  struct Node {
    Vector3d lo, hi;       ///< bounding box
    Vector3d area_vector;  ///< Σ ½ (x1−x0)×(x2−x0)
    Vector3d center;       ///< area-weighted centroid
    double radius = 0.0;   ///< max distance from center to the box corners
    int first = 0;         ///< leaf: first slot in m_order; inner: left child index
    int count = 0;         ///< leaf: number of triangles; inner: 0 (right child = left + 1)
  };
  void build(int self, int begin, int end, const std::vector<Vector3d>& centroids);

  MatrixX3d m_vertices;
  MatrixX3i m_triangles;
  std::vector<int> m_order;   ///< triangle indices, grouped by leaf
  std::vector<Node> m_nodes;  ///< m_nodes[0] is the root
};

}  // namespace strata
