#include "strata/core/sim/obstacle.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/common/error.hpp"
#include "strata/core/sim/ground_contact.hpp"

namespace strata {

Obstacle plane_obstacle(const std::string& name, const Vector3d& point, const Vector3d& normal) {
  if (!point.allFinite() || !normal.allFinite() || normal.norm() == 0.0)
    throw InputError(name + ": plane needs a finite point and a finite non-zero normal");
  const Vector3d n = normal.normalized();
  Obstacle obstacle;
  obstacle.name = name;
  obstacle.distance = [point, n](const Vector3d& p, Vector3d& gradient) {
    gradient = n;
    return n.dot(p - point);
  };
  return obstacle;
}

void validate_obstacle(const Obstacle& obstacle) {
  if (!obstacle.distance) throw InputError(obstacle.name + ": no distance function");
  if (!(obstacle.friction >= 0.0) || !std::isfinite(obstacle.friction))
    throw InputError(obstacle.name + ".friction: must be >= 0");
  if (!obstacle.velocity.allFinite())
    throw InputError(obstacle.name + ".motion.velocity: must be finite");
}

Index project_obstacle_contact(const std::vector<Obstacle>& obstacles, double t, VectorXd& x,
                               VectorXd& v, const std::vector<char>& skip, double* deepest) {
  Index contacts = 0;
  if (deepest != nullptr) *deepest = 0.0;
  for (const Obstacle& obstacle : obstacles) {
    for (Index i = 0; i < x.size() / 3; ++i) {
      if (!skip.empty() && skip[3 * i]) continue;
      Vector3d gradient;
      const double phi = obstacle.distance_at(x.segment<3>(3 * i), t, gradient);
      if (!(phi < 0.0) || gradient.norm() == 0.0) continue;
      ++contacts;
      if (deepest != nullptr) *deepest = std::max(*deepest, -phi);
      const Vector3d n = gradient.normalized();
      x.segment<3>(3 * i) -= phi * n;
      v.segment<3>(3 * i) =
          obstacle.velocity +
          contact_velocity_update(v.segment<3>(3 * i) - obstacle.velocity, n, obstacle.friction);
    }
  }
  return contacts;
}

}  // namespace strata
