#pragma once
/// \file scene_implicit.hpp
/// Parsing of the scene key "mesh": {"implicit": <shape>} (README, "Scene file and CLI
/// reference"): primitives and CSG trees.
#include "scene_json.hpp"
#include "strata/meshing/implicit_shape.hpp"

namespace strata::app::detail {

/// One shape: an object with exactly one of sphere, box, capsule, torus (primitives) or union,
/// intersection (arrays of ≥ 1 shapes), difference (an array of exactly 2 shapes). Errors name
/// the key path ("mesh.implicit.union.1.sphere.radius: must be > 0").
ImplicitShape parse_implicit_shape(const SceneValue& value);

}  // namespace strata::app::detail
