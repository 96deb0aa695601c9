#include "strata/core/sim/divergence_check.hpp"

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

void check_divergence(const ElasticModel& model, ConstRef<VectorXd> x, ConstRef<VectorXd> v,
                      const DivergenceLimits& limits, long step, double time,
                      const std::string& context) {
  const std::string where =
      context + ": step " + std::to_string(step) + ", t = " + std::to_string(time) + ": ";
  auto fail = [&](const std::string& what) { throw DivergenceError(where + what, step, time); };
  const VectorXd& rest = model.rest_positions();
  for (Index i = 0; i < x.size() / 3; ++i) {
    if (!x.segment<3>(3 * i).allFinite() || (v.size() > 0 && !v.segment<3>(3 * i).allFinite()))
      fail("non-finite position or velocity at vertex " + std::to_string(i));
    if (v.size() > 0 && v.segment<3>(3 * i).norm() > limits.max_speed)
      fail("vertex " + std::to_string(i) + " moves at " +
           std::to_string(v.segment<3>(3 * i).norm()) + " m/s, above the blow-up limit " +
           std::to_string(limits.max_speed) + " m/s (10 x P-wave speed); reduce dt");
    if ((x.segment<3>(3 * i) - rest.segment<3>(3 * i)).norm() > limits.max_displacement)
      fail("vertex " + std::to_string(i) + " displaced beyond the blow-up limit " +
           std::to_string(limits.max_displacement) + " m (100 x bounding-box diagonal)");
  }
  if (limits.check_inversion) {
    const auto [min_j, tet] = model.min_volume_ratio(x);
    if (!(min_j > 0.0))
      fail("element " + std::to_string(tet) + " inverted (J = " + std::to_string(min_j) + ") and " +
           to_string(model.material().model) + " cannot handle inversion");
  }
}

}  // namespace strata
