// The refinement indicator registry: each entry builds the indicator it names, the first entry is
// the settings' default, and an unknown name is refused with the full list.
#include <gtest/gtest.h>

#include <set>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/refinement_indicator_registry.hpp"

namespace strata {
namespace {

TEST(RefinementIndicatorRegistry, EachEntryBuildsTheIndicatorItNames) {
  const auto& registry = refinement_indicator_registry();
  ASSERT_FALSE(registry.empty());
  EXPECT_EQ(registry.front().name, HierarchySettings{}.indicator);
  std::set<std::string> names;
  for (const RefinementIndicatorTraits& traits : registry) {
    EXPECT_TRUE(names.insert(traits.name).second) << "duplicate " << traits.name;
    EXPECT_FALSE(traits.summary.empty()) << traits.name;
    const std::unique_ptr<RefinementIndicator> indicator = traits.make(0.01, RefinementSettings{});
    ASSERT_NE(indicator, nullptr) << traits.name;
    EXPECT_EQ(indicator->name(), traits.name);
    EXPECT_EQ(&refinement_indicator_traits(traits.name, "hierarchy.indicator"), &traits);
  }
}

TEST(RefinementIndicatorRegistry, UnknownNameListsEveryIndicator) {
  HierarchySettings settings;
  settings.levels = 2;
  settings.indicator = "curvature";
  try {
    validate_hierarchy_settings(settings, "hierarchy");
    FAIL() << "an unknown indicator was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("hierarchy.indicator"), std::string::npos) << message;
    EXPECT_NE(message.find("\"curvature\""), std::string::npos) << message;
    for (const std::string& name : refinement_indicator_names()) {
      std::string quoted = name;  // "name", built without operator+ (GCC 12's -Wrestrict)
      quoted.insert(quoted.begin(), '"');
      quoted.push_back('"');
      EXPECT_NE(message.find(quoted), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace strata
