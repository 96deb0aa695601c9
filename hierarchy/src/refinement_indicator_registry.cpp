#include "strata/hierarchy/refinement_indicator_registry.hpp"

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/refinement_force_indicator.hpp"
#include "strata/hierarchy/refinement_recovery_estimator.hpp"
#include "strata/hierarchy/refinement_stress_jump_indicator.hpp"

namespace strata {

const std::vector<RefinementIndicatorTraits>& refinement_indicator_registry() {
  static const std::vector<RefinementIndicatorTraits> registry = {
      {"recovery",
       "hierarchical error estimate: each tet's share of the displacement error its refinement "
       "would remove, relative to the tolerance",
       true,
       [](double tolerance, const RefinementSettings&) -> std::unique_ptr<RefinementIndicator> {
         return std::make_unique<RecoveryIndicator>(tolerance);
       }},
      {"force",
       "out-of-balance force at the vertices red refinement would add, relative to the tet's "
       "stiffness",
       false,
       [](double, const RefinementSettings& criteria) -> std::unique_ptr<RefinementIndicator> {
         return std::make_unique<ForceIndicator>(criteria.stress_floor);
       }},
      {"stress_jump", "largest jump of stress to the face neighbours, relative to the tet's stress",
       false,
       [](double, const RefinementSettings& criteria) -> std::unique_ptr<RefinementIndicator> {
         return std::make_unique<StressJumpIndicator>(criteria.stress_floor);
       }},
  };
  return registry;
}

std::vector<std::string> refinement_indicator_names() {
  std::vector<std::string> names;
  for (const RefinementIndicatorTraits& traits : refinement_indicator_registry())
    names.push_back(traits.name);
  return names;
}

const RefinementIndicatorTraits& refinement_indicator_traits(const std::string& name,
                                                             const std::string& where) {
  std::string expected;
  for (const RefinementIndicatorTraits& traits : refinement_indicator_registry()) {
    if (traits.name == name) return traits;
    expected += (expected.empty() ? "\"" : ", \"") + traits.name + "\"";
  }
  throw InputError(where + ": expected one of " + expected + ", got \"" + name + "\"");
}

}  // namespace strata
