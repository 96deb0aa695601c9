#pragma once
/// \file scene_hierarchy.hpp
/// Parsing of the scene key "hierarchy" (README, "Scene file and CLI reference").
#include "scene_json.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"

namespace strata::app::detail {

/// The "hierarchy" object; errors name the key path ("hierarchy.mode: unknown value ...").
HierarchySettings parse_hierarchy(const SceneValue& value);

}  // namespace strata::app::detail
