#pragma once
/// \file scene_hierarchy.hpp
/// Parsing of the scene key "hierarchy" (README, "Scene file and CLI reference").
#include <filesystem>

#include "scene_json.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"

namespace strata::app::detail {

/// The "hierarchy" object; errors name the key path ("hierarchy.mode: unknown value ...").
/// `folder`: the scene file's folder ("cut" is relative to it).
HierarchySettings parse_hierarchy(const SceneValue& value, const std::filesystem::path& folder);

}  // namespace strata::app::detail
