#include "strata/core/sim/ground_contact.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/common/error.hpp"

namespace strata {

void validate_ground(const GroundPlane& ground, const std::string& where) {
  if (!ground.point.allFinite() || !ground.normal.allFinite() || !std::isfinite(ground.friction))
    throw InputError(where + ": point, normal and friction must be finite");
  if (ground.normal.norm() == 0.0) throw InputError(where + ": normal must be non-zero");
  if (ground.friction < 0.0) throw InputError(where + ": friction must be >= 0");
}

Index project_ground_contact(const GroundPlane& ground, VectorXd& x, VectorXd& v,
                             const std::vector<char>& skip) {
  const Vector3d n = ground.normal.normalized();
  Index contacts = 0;
  for (Index i = 0; i < x.size() / 3; ++i) {
    if (!skip.empty() && skip[3 * i]) continue;
    const double depth = n.dot(x.segment<3>(3 * i) - ground.point);
    if (depth >= 0.0) continue;
    ++contacts;
    x.segment<3>(3 * i) -= depth * n;
    v.segment<3>(3 * i) = contact_velocity_update(v.segment<3>(3 * i), n, ground.friction);
  }
  return contacts;
}

Vector3d contact_velocity_update(const Vector3d& relative_velocity, const Vector3d& n,
                                 double friction) {
  const double v_n = n.dot(relative_velocity);
  const double dv_n = std::max(0.0, -v_n);
  const Vector3d v_t = relative_velocity - v_n * n;
  const double speed_t = v_t.norm();
  const double reduced = std::max(0.0, speed_t - friction * dv_n);
  const Vector3d new_t = speed_t > 0.0 ? Vector3d(v_t * (reduced / speed_t)) : Vector3d::Zero();
  return new_t + std::max(v_n, 0.0) * n;
}

double ground_penalty_stiffness(double youngs_modulus, double mean_edge_length, double factor) {
  return factor * youngs_modulus * mean_edge_length;
}

double ground_penalty_energy(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x) {
  const Vector3d n = ground.normal.normalized();
  double energy = 0.0;
  for (Index i = 0; i < x.size() / 3; ++i) {
    const double depth = n.dot(x.segment<3>(3 * i) - ground.point);
    if (depth < 0.0) energy += 0.5 * stiffness * depth * depth;
  }
  return energy;
}

void add_ground_penalty_gradient(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x,
                                 VectorXd& gradient) {
  const Vector3d n = ground.normal.normalized();
  for (Index i = 0; i < x.size() / 3; ++i) {
    const double depth = n.dot(x.segment<3>(3 * i) - ground.point);
    if (depth < 0.0) gradient.segment<3>(3 * i) += stiffness * depth * n;
  }
}

void add_ground_penalty_hessian(const GroundPlane& ground, double stiffness, ConstRef<VectorXd> x,
                                SparseMatrixd& H) {
  const Vector3d n = ground.normal.normalized();
  const Matrix3d block = stiffness * n * n.transpose();
  for (Index i = 0; i < x.size() / 3; ++i) {
    const double depth = n.dot(x.segment<3>(3 * i) - ground.point);
    if (depth >= 0.0) continue;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        H.coeffRef(3 * i + r, 3 * i + c) += block(r, c);
  }
}

}  // namespace strata
