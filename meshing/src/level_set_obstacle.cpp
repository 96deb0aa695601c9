#include "strata/meshing/level_set_obstacle.hpp"

namespace strata {

Obstacle level_set_obstacle(const std::string& name, std::shared_ptr<const LevelSet> level_set) {
  Obstacle obstacle;
  obstacle.name = name;
  obstacle.distance = [level_set](const Vector3d& p, Vector3d& gradient) {
    return level_set->smooth_signed_distance_and_gradient(p, gradient);
  };
  return obstacle;
}

}  // namespace strata
