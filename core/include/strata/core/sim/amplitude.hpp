#pragma once
/// \file amplitude.hpp
/// A load history: the factor s(t) that scales one load or one prescribed motion over a run.
///
/// A table of points (t_k, s_k), t strictly increasing, defines s(t) piecewise linearly between
/// them and constant beyond the ends (s(t) = s_0 for t < t_0, s_n for t > t_n). t is the time [s]
/// in dynamic runs and the load factor's pseudo-time λ ∈ [0, 1] in static runs. An empty table
/// stands for the run's default history: the ramp min(t / ramp_time, 1) of prescribed motion in
/// dynamic runs (loads stay constant), s = λ in static runs.
///
/// Example: a load that rises over the first half of a static run and comes back,
///   [[0, 0], [0.5, 1], [1, 0]].
#include <array>
#include <string>
#include <vector>

namespace strata {

struct Amplitude {
  std::vector<std::array<double, 2>> points;  ///< (t_k, s_k), t strictly increasing

  /// No table: the run's default history applies.
  bool empty() const { return points.empty(); }
  /// s(t) (needs a table).
  double value(double t) const;
  /// ds/dt on the segment that holds t (the later segment at a point t_k, 0 outside the table).
  double rate(double t) const;
  /// max_t |s(t)|.
  double peak() const;
  /// max |s(t)| over the interval between t0 and t1 (needs a table).
  double peak(double t0, double t1) const;
};

/// Throws InputError naming `where` (e.g. "forces[1].amplitude") unless every point is finite
/// and the times increase strictly. An empty table is valid.
void validate_amplitude(const Amplitude& amplitude, const std::string& where);

}  // namespace strata
