#include "strata/core/sim/region.hpp"

#include <cmath>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

bool is_finite(const Vector3d& v) {
  return v.allFinite();
}

}  // namespace

void validate_region(const Region& region, const std::string& where) {
  if (const auto* box = std::get_if<BoxRegion>(&region)) {
    if (!is_finite(box->min) || !is_finite(box->max))
      throw InputError(where + ": box corners must be finite");
    if ((box->min.array() > box->max.array()).any())
      throw InputError(where + ": box min must not exceed max in any coordinate");
  } else if (const auto* plane = std::get_if<PlaneRegion>(&region)) {
    if (!is_finite(plane->point) || !is_finite(plane->normal) || !std::isfinite(plane->distance))
      throw InputError(where + ": plane point, normal and distance must be finite");
    if (plane->normal.norm() == 0.0) throw InputError(where + ": plane normal must be non-zero");
    if (plane->distance < 0.0) throw InputError(where + ": plane distance must be >= 0");
  } else {
    const auto& sphere = std::get<SphereRegion>(region);
    if (!is_finite(sphere.center) || !std::isfinite(sphere.radius))
      throw InputError(where + ": sphere center and radius must be finite");
    if (sphere.radius < 0.0) throw InputError(where + ": sphere radius must be >= 0");
  }
}

double region_tolerance(ConstRef<MatrixX3d> rest_positions) {
  if (rest_positions.rows() == 0) return 0.0;
  const Vector3d lo = rest_positions.colwise().minCoeff().transpose();
  const Vector3d hi = rest_positions.colwise().maxCoeff().transpose();
  return 1e-9 * (hi - lo).norm();
}

std::vector<int> select_vertices(const Region& region, ConstRef<MatrixX3d> rest_positions,
                                 double tolerance) {
  std::vector<int> selected;
  const Index n = rest_positions.rows();
  auto keep_if = [&](auto&& inside) {
    for (Index v = 0; v < n; ++v) {
      const Vector3d X = rest_positions.row(v).transpose();
      if (inside(X)) selected.push_back(static_cast<int>(v));
    }
  };
  if (const auto* box = std::get_if<BoxRegion>(&region)) {
    keep_if([&](const Vector3d& X) {
      return (X.array() >= box->min.array() - tolerance).all() &&
             (X.array() <= box->max.array() + tolerance).all();
    });
  } else if (const auto* plane = std::get_if<PlaneRegion>(&region)) {
    const Vector3d n_hat = plane->normal.normalized();
    keep_if([&](const Vector3d& X) {
      return std::abs(n_hat.dot(X - plane->point)) <= plane->distance + tolerance;
    });
  } else {
    const auto& sphere = std::get<SphereRegion>(region);
    keep_if(
        [&](const Vector3d& X) { return (X - sphere.center).norm() <= sphere.radius + tolerance; });
  }
  return selected;
}

}  // namespace strata
