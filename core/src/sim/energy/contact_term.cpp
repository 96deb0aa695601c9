#include "strata/core/sim/energy/contact_term.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

/// f₁(y)/y and the smoothed friction potential f₀(y) for slip y ≥ 0 and tolerance ε.
double f1_over_y(double y, double epsilon) {
  return y < epsilon ? 2.0 / epsilon - y / (epsilon * epsilon) : 1.0 / y;
}
double f0(double y, double epsilon) {
  return y < epsilon ? y * y / epsilon - y * y * y / (3 * epsilon * epsilon) + epsilon / 3.0 : y;
}

}  // namespace

namespace {

std::vector<ContactPoint> unit_points(const std::vector<int>& vertices) {
  std::vector<ContactPoint> points;
  points.reserve(vertices.size());
  for (int v : vertices)
    points.push_back({{v}, {1.0}});
  return points;
}

/// Adds `block` to the 3×3 block (a, b) of `hessian`, which must hold it.
void add_block(SparseMatrixd& hessian, int a, int b, const Matrix3d& block) {
  for (int c = 0; c < 3; ++c) {
    const Index column = 3 * b + c;
    const int* begin = hessian.innerIndexPtr() + hessian.outerIndexPtr()[column];
    const int* end = hessian.innerIndexPtr() + hessian.outerIndexPtr()[column + 1];
    const int* row = std::lower_bound(begin, end, 3 * a);
    if (row == end || *row != 3 * a || row + 2 >= end)
      throw std::logic_error("ContactTerm: the Hessian pattern lacks a contact block");
    double* values = hessian.valuePtr() + (row - hessian.innerIndexPtr());
    for (int r = 0; r < 3; ++r)
      values[r] += block(r, c);
  }
}

/// "<obstacle>: <what> <index> starts D m inside the obstacle".
std::string deep_start(const Obstacle& obstacle, const std::string& what, Index index,
                       double depth) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", depth);
  return obstacle.name + ": " + what + " " + std::to_string(index) + " starts " + text +
         " m inside the obstacle";
}

}  // namespace

ContactTerm::ContactTerm(const std::vector<Obstacle>& obstacles, const std::vector<int>& vertices,
                         ContactSettings settings)
    : ContactTerm(obstacles, unit_points(vertices), settings) {}

ContactTerm::ContactTerm(const std::vector<Obstacle>& obstacles, std::vector<ContactPoint> points,
                         ContactSettings settings)
    : m_obstacles(obstacles), m_points(std::move(points)), m_settings(settings) {
  if (!(settings.distance > 0.0) || !(settings.stiffness > 0.0) || !(settings.friction_slip > 0.0))
    throw InputError("contact: distance, stiffness and friction_slip must be positive");
  for (const ContactPoint& point : m_points)
    if (point.vertices.empty() || point.vertices.size() != point.weights.size())
      throw std::invalid_argument("ContactTerm: a point needs one weight per vertex");
}

Vector3d ContactTerm::position(ConstRef<VectorXd> q, Index p) const {
  const ContactPoint& point = m_points[p];
  Vector3d x = Vector3d::Zero();
  for (size_t k = 0; k < point.vertices.size(); ++k)
    x += point.weights[k] * q.segment<3>(3 * point.vertices[k]);
  return x;
}

double ContactTerm::barrier(double d) const {
  const double dhat = m_settings.distance;
  if (d >= dhat) return 0.0;
  return -m_settings.stiffness * (d - dhat) * (d - dhat) * std::log(d / dhat);
}

double ContactTerm::barrier_derivative(double d) const {
  const double dhat = m_settings.distance;
  if (d >= dhat) return 0.0;
  return -m_settings.stiffness *
         (2.0 * (d - dhat) * std::log(d / dhat) + (d - dhat) * (d - dhat) / d);
}

double ContactTerm::barrier_second_derivative(double d) const {
  const double dhat = m_settings.distance;
  if (d >= dhat) return 0.0;
  return -m_settings.stiffness *
         (2.0 * std::log(d / dhat) + 4.0 * (d - dhat) / d - (d - dhat) * (d - dhat) / (d * d));
}

void ContactTerm::set_step(ConstRef<VectorXd> q0, double t0, double t1) {
  m_time = t1;
  m_friction.clear();
  for (size_t o = 0; o < m_obstacles.size(); ++o) {
    const Obstacle& obstacle = m_obstacles[o];
    if (obstacle.friction == 0.0) continue;
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d gradient;
      const Vector3d x0 = position(q0, p);
      const double d = obstacle.distance_at(x0, t0, gradient) + m_settings.distance;
      if (!(d > 0.0) || d >= m_settings.distance || gradient.norm() == 0.0) continue;
      const Vector3d n = gradient.normalized();
      const Vector3d seed = std::abs(n.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
      const Vector3d t1v = n.cross(seed).normalized();
      FrictionPair pair;
      pair.point = static_cast<int>(p);
      pair.obstacle = static_cast<int>(o);
      pair.weight = obstacle.friction * -barrier_derivative(d);
      pair.basis.col(0) = t1v;
      pair.basis.col(1) = n.cross(t1v);
      pair.reference = x0 + (t1 - t0) * obstacle.velocity;
      m_friction.push_back(pair);
    }
  }
}

double ContactTerm::value(ConstRef<VectorXd> q) const {
  double energy = 0.0;
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d gradient;
      const double d = obstacle.distance_at(position(q, p), m_time, gradient) + m_settings.distance;
      if (!(d > 0.0)) return std::numeric_limits<double>::infinity();
      energy += barrier(d);
    }
  const double epsilon = m_settings.friction_slip;
  for (const FrictionPair& pair : m_friction) {
    const Eigen::Vector2d u = pair.basis.transpose() * (position(q, pair.point) - pair.reference);
    energy += pair.weight * f0(u.norm(), epsilon);
  }
  return energy;
}

template <class Visit>
void ContactTerm::visit_gradients(ConstRef<VectorXd> q, bool friction, Visit&& visit) const {
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d n;
      const double d = obstacle.distance_at(position(q, p), m_time, n) + m_settings.distance;
      if (!(d > 0.0) || d >= m_settings.distance) continue;
      visit(p, Vector3d(barrier_derivative(d) * n));
    }
  if (!friction) return;
  const double epsilon = m_settings.friction_slip;
  for (const FrictionPair& pair : m_friction) {
    const Eigen::Vector2d u = pair.basis.transpose() * (position(q, pair.point) - pair.reference);
    visit(pair.point, Vector3d(pair.weight * f1_over_y(u.norm(), epsilon) * (pair.basis * u)));
  }
}

void ContactTerm::add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  visit_gradients(q, true, [&](Index p, const Vector3d& g) {
    const ContactPoint& point = m_points[p];
    for (size_t k = 0; k < point.vertices.size(); ++k)
      gradient.segment<3>(3 * point.vertices[k]) += point.weights[k] * g;
  });
}

std::vector<Vector3d> ContactTerm::point_forces(ConstRef<VectorXd> q, bool friction) const {
  std::vector<Vector3d> forces(m_points.size(), Vector3d::Zero());
  visit_gradients(q, friction, [&](Index p, const Vector3d& g) { forces[p] -= g; });
  return forces;
}

void ContactTerm::add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool) const {
  const auto scatter = [&](Index p, const Matrix3d& block) {
    const ContactPoint& point = m_points[p];
    for (size_t a = 0; a < point.vertices.size(); ++a)
      for (size_t b = 0; b < point.vertices.size(); ++b)
        add_block(hessian, point.vertices[a], point.vertices[b],
                  point.weights[a] * point.weights[b] * block);
  };
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d n;
      const double d = obstacle.distance_at(position(q, p), m_time, n) + m_settings.distance;
      if (!(d > 0.0) || d >= m_settings.distance) continue;
      scatter(p, barrier_second_derivative(d) * n * n.transpose());
    }
  const double epsilon = m_settings.friction_slip;
  for (const FrictionPair& pair : m_friction) {
    const Eigen::Vector2d u = pair.basis.transpose() * (position(q, pair.point) - pair.reference);
    const double y = u.norm();
    Eigen::Matrix2d M;
    if (y >= epsilon) {
      M = (Eigen::Matrix2d::Identity() - u * u.transpose() / (y * y)) / y;
    } else {
      M = f1_over_y(y, epsilon) * Eigen::Matrix2d::Identity();
      if (y > 0.0) M -= u * u.transpose() / (epsilon * epsilon * y);
    }
    scatter(pair.point, pair.weight * pair.basis * M * pair.basis.transpose());
  }
}

double ContactTerm::max_step(ConstRef<VectorXd> q, ConstRef<VectorXd> step) const {
  // A point may close its room r = φ + d̂ to a tenth along the step. Where φ is 1-Lipschitz,
  // r(t) ≥ r₀ − t‖Δx‖: no point needs a closer look while 0.9 r₀ / ‖Δx‖ ≥ α. A point that would
  // limit α by that bound (a point in contact, sliding) is followed along its path: jumps of
  // 0.9 r (which cannot cross the surface) while it is far, samples d̂ apart near the surface,
  // and α where r falls to a tenth of r₀ (interpolated between samples, then halved towards the
  // last sample until r there is above a twentieth of r₀).
  constexpr double kKeep = 0.1;      // the fraction of its room a point keeps
  constexpr int kMaxSamples = 4096;  // per point and obstacle
  constexpr int kMaxHalvings = 30;
  const double spacing = m_settings.distance;
  double alpha = 1.0;
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      const Vector3d move = position(step, p);
      const double length = move.norm();
      if (length == 0.0) continue;
      const Vector3d start = position(q, p);
      Vector3d n;
      const auto room_at = [&](double t) {
        return obstacle.distance_at(start + t * move, m_time, n) + m_settings.distance;
      };
      const double room = room_at(0.0);
      if (!(room > 0.0) || (1.0 - kKeep) * room >= alpha * length) continue;
      const double target = kKeep * room;
      double t = 0.0, r = room;  // the last sample, r > target
      for (int sample = 0; sample < kMaxSamples && t < alpha; ++sample) {
        const double next_t = std::min(alpha, t + std::max(0.9 * r, spacing) / length);
        const double next_r = room_at(next_t);
        if (!std::isfinite(next_r)) {
          alpha = t;
          break;
        }
        if (next_r <= target) {
          // r crosses the target between t and next_t (r > target ≥ next_r).
          double end = t + (next_t - t) * (r - target) / (r - next_r);
          for (int halving = 0; halving < kMaxHalvings && !(room_at(end) > 0.5 * target); ++halving)
            end = t + 0.5 * (end - t);
          alpha = std::min(alpha, end);
          break;
        }
        t = next_t;
        r = next_r;
        if (sample + 1 == kMaxSamples) alpha = std::min(alpha, t);
      }
    }
  return alpha;
}

Index ContactTerm::add_normal_forces(ConstRef<VectorXd> q, VectorXd& f) const {
  Index active = 0;
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d n;
      const double d = obstacle.distance_at(position(q, p), m_time, n) + m_settings.distance;
      if (!(d > 0.0) || d >= m_settings.distance) continue;
      const ContactPoint& point = m_points[p];
      for (size_t k = 0; k < point.vertices.size(); ++k)
        f.segment<3>(3 * point.vertices[k]) -= point.weights[k] * barrier_derivative(d) * n;
      ++active;
    }
  return active;
}

void ContactTerm::require_feasible(ConstRef<VectorXd> q, const std::string& point_name) const {
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d gradient;
      const double phi = obstacle.distance_at(position(q, p), m_time, gradient);
      if (!(phi > -m_settings.distance)) {
        char tolerance[32];
        std::snprintf(tolerance, sizeof tolerance, "%.3g", m_settings.distance);
        throw InputError(deep_start(obstacle, point_name, p, -phi) +
                         " (more than the contact tolerance " + tolerance + " m)");
      }
    }
}

void ContactTerm::require_clear_inside(ConstRef<VectorXd> x) const {
  for (const Obstacle& obstacle : m_obstacles)
    for (Index v = 0; v < x.size() / 3; ++v) {
      Vector3d gradient;
      const double phi = obstacle.distance_at(x.segment<3>(3 * v), m_time, gradient);
      if (!(phi > -m_settings.distance))
        throw InputError(deep_start(obstacle, "mesh vertex", v, -phi) +
                         ": the obstacle overlaps the body's inside, where no contact point can "
                         "meet it");
    }
}

double ContactTerm::push_out(VectorXd& q, const std::vector<char>& constrained, double depth,
                             double to_depth) const {
  const double limit = depth * m_settings.distance;
  const double target = std::min(to_depth, depth) * m_settings.distance;
  VectorXd moved = VectorXd::Zero(q.size());
  for (int pass = 0; pass < 20; ++pass) {
    // Each deep point's least-norm lift, averaged over the points that share a DOF: points
    // embedded in one coarse face (a fine surface, the finest level's boundary) move its few
    // vertices together, and their summed lifts would overshoot by their number.
    VectorXd correction = VectorXd::Zero(q.size());
    VectorXd sharing = VectorXd::Zero(q.size());
    bool inside = false;
    for (const Obstacle& obstacle : m_obstacles)
      for (Index p = 0; p < num_points(); ++p) {
        Vector3d n;
        const double phi = obstacle.distance_at(position(q, p), m_time, n);
        if (!(phi < -limit)) continue;
        inside = true;
        const ContactPoint& point = m_points[p];
        double weight_sq = 0.0;
        for (size_t k = 0; k < point.vertices.size(); ++k)
          if (!constrained[3 * point.vertices[k]]) weight_sq += point.weights[k] * point.weights[k];
        if (weight_sq == 0.0) continue;
        const Vector3d lift = (-phi - target) * n.normalized() / weight_sq;
        for (size_t k = 0; k < point.vertices.size(); ++k)
          for (int c = 0; c < 3; ++c)
            if (!constrained[3 * point.vertices[k] + c] && point.weights[k] != 0.0) {
              correction[3 * point.vertices[k] + c] += point.weights[k] * lift[c];
              sharing[3 * point.vertices[k] + c] += 1.0;
            }
      }
    if (!inside) break;
    for (Index i = 0; i < correction.size(); ++i)
      if (sharing[i] > 1.0) correction[i] /= sharing[i];
    q += correction;
    moved += correction;
  }
  double largest = 0.0;
  for (Index v = 0; v < moved.size() / 3; ++v)
    largest = std::max(largest, moved.segment<3>(3 * v).norm());
  return largest;
}

double ContactTerm::min_distance(ConstRef<VectorXd> q) const {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Obstacle& obstacle : m_obstacles)
    for (Index p = 0; p < num_points(); ++p) {
      Vector3d n;
      smallest = std::min(smallest, obstacle.distance_at(position(q, p), m_time, n));
    }
  return smallest;
}

}  // namespace strata
