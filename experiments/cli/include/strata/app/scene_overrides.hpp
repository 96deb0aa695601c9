#pragma once
/// \file scene_overrides.hpp
/// Command-line overrides of scene keys: `--set key.path=value`.
///
/// The path is dotted; numeric components index arrays ("fixed.0.box.min"), and the index equal
/// to an array's size appends. Missing object keys along the path are created (the scene parser
/// then rejects keys that the scene format does not know). The value is parsed as JSON and falls
/// back to a plain string: `solver.dt=1e-4`, `gravity=[0,0,-9.81]`, `solver.mode=static`.
#include <string>

#include <nlohmann/json.hpp>

namespace strata::app {

struct SceneOverride {
  std::string path;      ///< dotted key path
  nlohmann::json value;  ///< new value
};

/// Splits "key.path=value". Throws InputError "--set <text>: expected key.path=value" when there
/// is no '=' or the path is empty or has an empty component.
SceneOverride parse_override(const std::string& text);

/// Sets the value at the override's path in `root`. Throws InputError "--set <path>: ..." when a
/// component crosses a non-container (a number, string...), an array index is not a number or is
/// beyond the array's end.
void apply_override(nlohmann::json& root, const SceneOverride& override_);

}  // namespace strata::app
