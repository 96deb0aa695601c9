#include "strata/core/sim/amplitude.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

/// Index k of the segment [t_k, t_{k+1}) that holds t; −1 before the table, n − 1 after it.
long segment_of(const std::vector<std::array<double, 2>>& points, double t) {
  const auto after = std::upper_bound(points.begin(), points.end(), t,
                                      [](double value, const auto& p) { return value < p[0]; });
  return static_cast<long>(after - points.begin()) - 1;
}

}  // namespace

double Amplitude::value(double t) const {
  STRATA_VERIFY(!points.empty(), "Amplitude::value needs a table");
  const long k = segment_of(points, t);
  if (k < 0) return points.front()[1];
  if (k + 1 >= static_cast<long>(points.size())) return points.back()[1];
  const auto& a = points[k];
  const auto& b = points[k + 1];
  const double w = (t - a[0]) / (b[0] - a[0]);
  return (1.0 - w) * a[1] + w * b[1];
}

double Amplitude::rate(double t) const {
  STRATA_VERIFY(!points.empty(), "Amplitude::rate needs a table");
  const long k = segment_of(points, t);
  if (k < 0 || k + 1 >= static_cast<long>(points.size())) return 0.0;
  const auto& a = points[k];
  const auto& b = points[k + 1];
  return (b[1] - a[1]) / (b[0] - a[0]);
}

double Amplitude::peak() const {
  double peak = 0.0;
  for (const auto& p : points)
    peak = std::max(peak, std::abs(p[1]));
  return peak;
}

double Amplitude::peak(double t0, double t1) const {
  if (t1 < t0) std::swap(t0, t1);
  // Piecewise linear: the largest magnitude is at an end or at a table point between them.
  double peak = std::max(std::abs(value(t0)), std::abs(value(t1)));
  for (const auto& p : points)
    if (p[0] > t0 && p[0] < t1) peak = std::max(peak, std::abs(p[1]));
  return peak;
}

void validate_amplitude(const Amplitude& amplitude, const std::string& where) {
  for (size_t k = 0; k < amplitude.points.size(); ++k) {
    const auto& p = amplitude.points[k];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
      throw InputError(where + "[" + std::to_string(k) + "]: must be two finite numbers [t, s]");
    if (k > 0 && !(p[0] > amplitude.points[k - 1][0]))
      throw InputError(where + "[" + std::to_string(k) + "]: times must increase strictly");
  }
}

}  // namespace strata
