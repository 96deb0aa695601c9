#pragma once
/// \file level_set_obstacle.hpp
/// A rigid obstacle (core's obstacle.hpp) whose signed distance is a level set: the C¹ tricubic
/// φ and its gradient (LevelSet::smooth_signed_distance_and_gradient), +background (no contact)
/// outside the narrow band.
#include <memory>
#include <string>

#include "strata/core/sim/obstacle.hpp"
#include "strata/meshing/level_set.hpp"

namespace strata {

/// The obstacle shares `level_set` (kept alive by the obstacle).
Obstacle level_set_obstacle(const std::string& name, std::shared_ptr<const LevelSet> level_set);

}  // namespace strata
