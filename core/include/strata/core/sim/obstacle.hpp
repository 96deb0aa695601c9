#pragma once
/// \file obstacle.hpp
/// Rigid obstacles for contact (energy/contact_term.hpp): a signed distance φ (negative inside,
/// 1-Lipschitz) with its gradient, a Coulomb friction coefficient and an optional rigid
/// translation over time. Core provides planes and arbitrary distance functions; level sets
/// (OpenVDB) come from the meshing module through `distance`.
#include <functional>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct Obstacle {
  std::string name;  ///< for messages, e.g. "obstacles.0"
  /// φ(p) [m] at a point of the obstacle's own frame; writes ∇φ (unit length where φ is a
  /// distance) into `gradient`.
  std::function<double(const Vector3d& p, Vector3d& gradient)> distance;
  double friction = 0.0;                 ///< Coulomb μ ≥ 0
  Vector3d velocity = Vector3d::Zero();  ///< rigid translation [m/s]: φ_t(x) = φ(x − v t)

  /// φ_t(x) and its gradient at time t (static runs: t = 0).
  double distance_at(const Vector3d& x, double t, Vector3d& gradient) const {
    return distance(x - t * velocity, gradient);
  }
};

/// The half-space behind a plane: φ(p) = n̂·(p − point), n̂ pointing into free space.
Obstacle plane_obstacle(const std::string& name, const Vector3d& point, const Vector3d& normal);

/// Throws InputError naming the obstacle unless it has a distance function, μ ≥ 0 and a finite
/// velocity.
void validate_obstacle(const Obstacle& obstacle);

/// Explicit integrators: every vertex inside an obstacle (φ < 0; not `skip[3 i]`) is moved onto
/// its surface along ∇φ, its inward normal velocity relative to the obstacle removed and its
/// tangential relative speed reduced by μ |Δv_n| (clamped at 0). Returns the vertex–obstacle
/// pairs projected, and in `deepest` (if given) the largest depth −φ a vertex had reached (0
/// when none was inside).
Index project_obstacle_contact(const std::vector<Obstacle>& obstacles, double t, VectorXd& x,
                               VectorXd& v, const std::vector<char>& skip,
                               double* deepest = nullptr);

}  // namespace strata
