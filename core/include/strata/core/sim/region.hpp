#pragma once
/// \file region.hpp
/// Geometric regions that select mesh vertices by their rest positions (for Dirichlet groups and
/// loads). Every test is inclusive and widened by a tolerance, so vertices lying exactly on a
/// region's boundary are selected despite round-off.
#include <string>
#include <variant>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

/// Axis-aligned box [min, max] [m].
struct BoxRegion {
  Vector3d min = Vector3d::Zero();
  Vector3d max = Vector3d::Zero();
};

/// Slab of vertices within `distance` [m] of the plane through `point` with normal `normal`
/// (need not be unit length, must be non-zero).
struct PlaneRegion {
  Vector3d point = Vector3d::Zero();
  Vector3d normal = Vector3d::UnitZ();
  double distance = 0.0;
};

/// Closed ball of radius `radius` [m] around `center`.
struct SphereRegion {
  Vector3d center = Vector3d::Zero();
  double radius = 0.0;
};

using Region = std::variant<BoxRegion, PlaneRegion, SphereRegion>;

/// Throws InputError naming `where` (e.g. "dirichlet.fixed[1].region") if the region is malformed:
/// non-finite numbers, min > max, zero normal, negative distance or radius.
void validate_region(const Region& region, const std::string& where);

/// The selection tolerance strata uses: 1e-9 × the diagonal of the bounding box of
/// `rest_positions` (#V × 3).
double region_tolerance(ConstRef<MatrixX3d> rest_positions);

/// Indices (ascending) of the vertices whose rest positions (#V × 3) lie in the region widened by
/// `tolerance` [m]: box min − tol ≤ X ≤ max + tol; plane |n̂·(X − p)| ≤ distance + tol;
/// sphere ‖X − c‖ ≤ radius + tol.
std::vector<int> select_vertices(const Region& region, ConstRef<MatrixX3d> rest_positions,
                                 double tolerance);

}  // namespace strata
