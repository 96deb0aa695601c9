// OpenVDB translation unit 2 of 2: level sets of analytic distance functions, and CSG.
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <cmath>

#include "level_set_impl.hpp"
#include "strata/core/common/error.hpp"

namespace strata {
namespace {

constexpr int kBlock = 8;  // = OpenVDB leaf edge, so blocks fill whole leaves

void check_finite(const Vector3d& v, const std::string& what) {
  if (!v.allFinite()) throw InputError(what + " must be finite");
}

void check_positive(double value, const std::string& what) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw InputError(what + " must be a positive number, got " + std::to_string(value));
}

LevelSet csg(const LevelSet& a, const LevelSet& b, const char* operation) {
  const openvdb::FloatGrid& ga = *a.impl().grid;
  const openvdb::FloatGrid& gb = *b.impl().grid;
  if (ga.transform() != gb.transform())
    throw InputError(std::string("level set ") + operation +
                     ": the two level sets have different voxel sizes or offsets");
  openvdb::FloatGrid::Ptr result;
  if (operation[0] == 'u')
    result = openvdb::tools::csgUnionCopy(ga, gb);
  else if (operation[0] == 'i')
    result = openvdb::tools::csgIntersectionCopy(ga, gb);
  else
    result = openvdb::tools::csgDifferenceCopy(ga, gb);
  result->setTransform(ga.transform().copy());
  result->setName(ga.getName() + "_" + operation + "_" + gb.getName());
  return detail::wrap_level_set(result);
}

}  // namespace

LevelSet level_set_from_function(const std::function<double(const Vector3d&)>& sdf,
                                 const Vector3d& lo, const Vector3d& hi,
                                 const LevelSetOptions& options, const std::string& name) {
  detail::check_level_set_options(options, "level set '" + name + "'");
  check_finite(lo, "level set '" + name + "': box minimum");
  check_finite(hi, "level set '" + name + "': box maximum");
  detail::check_level_set_size(lo, hi, options, "level set '" + name + "'");
  detail::ensure_openvdb_initialized();
  const double h = options.voxel_size;
  const double background = options.half_width * h;
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(static_cast<float>(background));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
  grid->setName(name);

  // Index range: the box grown by the band, rounded out to whole blocks.
  const int pad = static_cast<int>(std::ceil(options.half_width)) + 1;
  int first[3], last[3];
  for (int a = 0; a < 3; ++a) {
    const double lo_index = std::floor(std::min(lo(a), hi(a)) / h) - pad;
    const double hi_index = std::ceil(std::max(lo(a), hi(a)) / h) + pad;
    if (hi_index - lo_index > 1 << 20)
      throw InputError("level set '" + name + "': more than 2^20 voxels along an axis");
    first[a] = static_cast<int>(std::floor(lo_index / kBlock)) * kBlock;
    last[a] = static_cast<int>(std::ceil((hi_index + 1) / kBlock)) * kBlock;
  }
  openvdb::FloatGrid::Accessor accessor = grid->getAccessor();
  // Lipschitz bound: a block whose centre is farther than band + half-diagonal holds no band voxel.
  const double block_reach = background + 0.5 * std::sqrt(3.0) * (kBlock - 1) * h;
  for (int bk = first[2]; bk < last[2]; bk += kBlock) {
    for (int bj = first[1]; bj < last[1]; bj += kBlock) {
      for (int bi = first[0]; bi < last[0]; bi += kBlock) {
        const Vector3d block_center =
            h * (Vector3d(bi, bj, bk) + Vector3d::Constant(0.5 * (kBlock - 1)));
        if (std::abs(sdf(block_center)) > block_reach) continue;
        for (int k = bk; k < bk + kBlock; ++k)
          for (int j = bj; j < bj + kBlock; ++j)
            for (int i = bi; i < bi + kBlock; ++i) {
              const double d = sdf(h * Vector3d(i, j, k));
              if (std::abs(d) < background)
                accessor.setValue(openvdb::Coord(i, j, k), static_cast<float>(d));
              else  // inactive, but with the right sign for the flood fill
                accessor.setValueOff(openvdb::Coord(i, j, k),
                                     static_cast<float>(d < 0.0 ? -background : background));
            }
      }
    }
  }
  openvdb::tools::signedFloodFill(grid->tree());
  openvdb::tools::pruneLevelSet(grid->tree());
  return detail::wrap_level_set(grid);
}

LevelSet level_set_sphere(const Vector3d& center, double radius, const LevelSetOptions& options) {
  check_finite(center, "level set sphere: center");
  check_positive(radius, "level set sphere: radius");
  return level_set_from_function([&](const Vector3d& x) { return (x - center).norm() - radius; },
                                 center.array() - radius, center.array() + radius, options,
                                 "sphere");
}

LevelSet level_set_box(const Vector3d& min, const Vector3d& max, const LevelSetOptions& options) {
  check_finite(min, "level set box: min");
  check_finite(max, "level set box: max");
  if (!((max - min).array() > 0.0).all()) throw InputError("level set box: max must exceed min");
  const Vector3d center = 0.5 * (min + max);
  const Vector3d half = 0.5 * (max - min);
  return level_set_from_function(
      [&](const Vector3d& x) {
        const Vector3d q = (x - center).cwiseAbs() - half;
        return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
      },
      min, max, options, "box");
}

LevelSet level_set_capsule(const Vector3d& a, const Vector3d& b, double radius,
                           const LevelSetOptions& options) {
  check_finite(a, "level set capsule: a");
  check_finite(b, "level set capsule: b");
  check_positive(radius, "level set capsule: radius");
  const Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  return level_set_from_function(
      [&](const Vector3d& x) {
        const double s =
            length_squared > 0.0 ? std::clamp((x - a).dot(ab) / length_squared, 0.0, 1.0) : 0.0;
        return (x - a - s * ab).norm() - radius;
      },
      a.cwiseMin(b).array() - radius, a.cwiseMax(b).array() + radius, options, "capsule");
}

LevelSet level_set_torus(const Vector3d& center, const Vector3d& axis, double major_radius,
                         double minor_radius, const LevelSetOptions& options) {
  check_finite(center, "level set torus: center");
  check_positive(axis.norm(), "level set torus: axis length");
  check_positive(major_radius, "level set torus: major radius");
  check_positive(minor_radius, "level set torus: minor radius");
  const Vector3d n = axis.normalized();
  const double reach = major_radius + minor_radius;
  return level_set_from_function(
      [&](const Vector3d& x) {
        const Vector3d r = x - center;
        const double height = r.dot(n);
        const double planar = (r - height * n).norm();
        return std::hypot(planar - major_radius, height) - minor_radius;
      },
      center.array() - reach, center.array() + reach, options, "torus");
}

LevelSet csg_union(const LevelSet& a, const LevelSet& b) {
  return csg(a, b, "union");
}
LevelSet csg_intersection(const LevelSet& a, const LevelSet& b) {
  return csg(a, b, "intersection");
}
LevelSet csg_difference(const LevelSet& a, const LevelSet& b) {
  return csg(a, b, "difference");
}

}  // namespace strata
