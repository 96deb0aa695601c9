#pragma once
/// \file point_location.hpp
/// Point location in a rest tet mesh: which tet contains a point, and the point's barycentric
/// coordinates in it. A uniform grid over the mesh's bounding box buckets the tets by their
/// bounding boxes, so a query tests only the few tets of one cell (or of the cells within the
/// tolerance, for points just outside the mesh).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

/// Barycentric coordinates (λ0, λ1, λ2, λ3) of `p` in the tet (x0, x1, x2, x3): Σλ = 1 and
/// Σ λ_k x_k = p. All λ ≥ 0 iff p lies in the tet; points outside get (some) negative λ.
/// Requires a non-degenerate tet.
Eigen::Vector4d tet_barycentric_coordinates(const Vector3d& p, const Vector3d& x0,
                                            const Vector3d& x1, const Vector3d& x2,
                                            const Vector3d& x3);

/// Euclidean distance from `p` to the (solid) tet (x0, x1, x2, x3); 0 inside.
double point_tet_distance(const Vector3d& p, const Vector3d& x0, const Vector3d& x1,
                          const Vector3d& x2, const Vector3d& x3);

/// Where a point lies in a mesh.
struct TetLocation {
  Index tet = -1;               ///< index of the containing (or nearest) tet
  Eigen::Vector4d barycentric;  ///< coordinates of the point in that tet (sum 1, reproduce it)
  double distance = 0.0;        ///< distance from the point to that tet [m]; 0 inside
};

/// Grid-accelerated point location in a fixed tet mesh (rest configuration).
///
/// The grid has about one cell per tet (at most 128 per axis); each cell lists the tets whose
/// bounding boxes overlap it. Building costs O(#T), a query O(tets per cell).
class TetLocator {
 public:
  /// `vertices` #V × 3, `tets` #T × 4 (non-degenerate; orientation does not matter).
  TetLocator(ConstRef<MatrixX3d> vertices, ConstRef<MatrixX4i> tets);

  /// The tet containing `p` (all barycentric coordinates ≥ −1e-12), else the nearest tet if its
  /// distance to `p` is at most `tolerance` [m], else nothing. The returned barycentric
  /// coordinates are those of `p` itself (slightly negative for points just outside).
  std::optional<TetLocation> locate(const Vector3d& p, double tolerance) const;

  /// Grid resolution (cells per axis).
  const std::array<int, 3>& grid_size() const { return m_cells; }

 private:
  std::array<int, 3> cell_of(const Vector3d& p) const;
  TetLocation evaluate(Index tet, const Vector3d& p) const;

  MatrixX3d m_vertices;
  MatrixX4i m_tets;
  Vector3d m_origin;
  Vector3d m_cell_size;
  std::array<int, 3> m_cells{1, 1, 1};
  std::vector<int> m_cell_start;  ///< CSR offsets, one per cell plus one
  std::vector<int> m_cell_tets;   ///< tet indices, grouped by cell
};

/// Locates every row of `points` (#P × 3) with `tolerance` [m]. Throws InputError
/// "<what>.<i>: point (x, y, z) lies outside the mesh" for the first point that is not found
/// (e.g. what = "output.probes").
std::vector<TetLocation> locate_points(const TetLocator& locator, ConstRef<MatrixX3d> points,
                                       double tolerance, const std::string& what);

}  // namespace strata
