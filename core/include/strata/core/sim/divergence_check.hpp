#pragma once
/// \file divergence_check.hpp
/// Per-step detection of a run that left the valid state space. Criteria, in order:
/// 1. any non-finite position or velocity;
/// 2. blow-up: a vertex speed above `max_speed` (default 10 × the P-wave speed: no elastic motion
///    moves material faster than its waves, so an exponentially growing explicit instability trips
///    this within a few steps) or a displacement from rest above `max_displacement` (default 100 ×
///    the bounding-box diagonal);
/// 3. an inverted element (J = det F ≤ 0) when the material cannot handle inversion (StVK).
/// A violation throws DivergenceError naming the step, the time and the vertex or element, with
/// its rest position (an element's: its centroid).
#include "strata/core/common/types.hpp"
#include "strata/core/fem/elastic_model.hpp"

namespace strata {

struct DivergenceLimits {
  double max_speed = 0.0;         ///< [m/s]
  double max_displacement = 0.0;  ///< [m]
  bool check_inversion = false;   ///< true for materials without handles_inversion
};

/// The defaults described above for `material` and a mesh of bounding-box diagonal `diagonal`.
DivergenceLimits default_divergence_limits(const Material& material, double diagonal);

/// Throws DivergenceError (step, time; `context` e.g. "rk4") if the state (x, v: 3·#V) violates a
/// limit. `v` may be empty (static runs). `volume_ratio`, when given, is the smallest volume ratio
/// at x computed with the forces (ElasticModel::forces_and_min_volume_ratio: det F, equal to
/// min_volume_ratio's det(Ds) det(Dm⁻¹) up to round-off), used instead of a pass over the tets.
void check_divergence(const ElasticModel& model, ConstRef<VectorXd> x, ConstRef<VectorXd> v,
                      const DivergenceLimits& limits, long step, double time,
                      const std::string& context,
                      const std::pair<double, Index>* volume_ratio = nullptr);

}  // namespace strata
