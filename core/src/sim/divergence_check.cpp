#include "strata/core/sim/divergence_check.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "strata/core/common/error.hpp"

namespace strata {

DivergenceLimits default_divergence_limits(const Material& material, double diagonal) {
  DivergenceLimits limits;
  limits.max_speed = 10.0 * material.p_wave_speed();
  limits.max_displacement = 100.0 * diagonal;
  limits.check_inversion = !handles_inversion(material.model);
  return limits;
}

namespace {

/// " (at rest (x, y, z) m)": where a vertex or element is, whatever its numbering (a hierarchy
/// numbers the tets and vertices of its current cut).
std::string rest_location(const Vector3d& p) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), " (at rest (%.4g, %.4g, %.4g) m)", p.x(), p.y(), p.z());
  return buffer;
}

}  // namespace

void check_divergence(const ElasticModel& model, ConstRef<VectorXd> x, ConstRef<VectorXd> v,
                      const DivergenceLimits& limits, long step, double time,
                      const std::string& context, const std::pair<double, Index>* volume_ratio) {
  const std::string where =
      context + ": step " + std::to_string(step) + ", t = " + std::to_string(time) + ": ";
  auto fail = [&](const std::string& what) { throw DivergenceError(where + what, step, time); };
  const VectorXd& rest = model.rest_positions();
  const auto vertex = [&](Index i) {
    return "vertex " + std::to_string(i) + rest_location(rest.segment<3>(3 * i));
  };
  const Index num_vertices = x.size() / 3;
  const bool has_v = v.size() > 0;
  auto vertex_fails = [&](Index i) {
    if (!x.segment<3>(3 * i).allFinite() || (has_v && !v.segment<3>(3 * i).allFinite()))
      return true;
    if (has_v && v.segment<3>(3 * i).norm() > limits.max_speed) return true;
    return (x.segment<3>(3 * i) - rest.segment<3>(3 * i)).norm() > limits.max_displacement;
  };
  // The first failing vertex (smallest index, on any schedule), then its message.
  const Index first = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, num_vertices, 8192), num_vertices,
      [&](const tbb::blocked_range<Index>& range, Index found) {
        for (Index i = range.begin(); i != range.end() && i < found; ++i)
          if (vertex_fails(i)) return i;
        return found;
      },
      [](Index a, Index b) { return std::min(a, b); });
  if (first < num_vertices) {
    const Index i = first;
    if (!x.segment<3>(3 * i).allFinite() || (has_v && !v.segment<3>(3 * i).allFinite()))
      fail("non-finite position or velocity at " + vertex(i));
    if (has_v && v.segment<3>(3 * i).norm() > limits.max_speed)
      fail(vertex(i) + " moves at " + std::to_string(v.segment<3>(3 * i).norm()) +
           " m/s, above the blow-up limit " + std::to_string(limits.max_speed) +
           " m/s (10 x P-wave speed); reduce dt");
    fail(vertex(i) + " displaced beyond the blow-up limit " +
         std::to_string(limits.max_displacement) + " m (100 x bounding-box diagonal)");
  }
  if (limits.check_inversion) {
    const auto [min_j, tet] = volume_ratio != nullptr ? *volume_ratio : model.min_volume_ratio(x);
    if (!(min_j > 0.0)) {
      Vector3d centroid = Vector3d::Zero();
      for (int k = 0; k < 4; ++k)
        centroid += 0.25 * rest.segment<3>(3 * model.tets()(tet, k));
      fail("element " + std::to_string(tet) + rest_location(centroid) +
           " inverted (J = " + std::to_string(min_j) + ") and " +
           to_string(model.material().model) + " cannot handle inversion");
    }
  }
}

}  // namespace strata
