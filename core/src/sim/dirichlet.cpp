#include "strata/core/sim/dirichlet.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "strata/core/common/error.hpp"

namespace strata {

double DirichletGroup::factor(double t, double default_s) const {
  return spec.amplitude.empty() ? default_s : spec.amplitude.value(t);
}

double DirichletGroup::factor_rate(double t, double default_rate) const {
  return spec.amplitude.empty() ? default_rate : spec.amplitude.rate(t);
}

Vector3d DirichletGroup::target_position(const Vector3d& X, double s) const {
  switch (spec.kind) {
    case DirichletKind::fixed:
      return X;
    case DirichletKind::displacement:
      return X + s * spec.displacement;
    case DirichletKind::rotation: {
      const Eigen::AngleAxisd rotation(s * spec.angle, spec.axis.normalized());
      return moment_center + rotation * (X - moment_center);
    }
  }
  return X;
}

Vector3d DirichletGroup::target_velocity(const Vector3d& X, double s, double ds_dt) const {
  switch (spec.kind) {
    case DirichletKind::fixed:
      return Vector3d::Zero();
    case DirichletKind::displacement:
      return ds_dt * spec.displacement;
    case DirichletKind::rotation: {
      const Vector3d omega = ds_dt * spec.angle * spec.axis.normalized();
      return omega.cross(target_position(X, s) - moment_center);
    }
  }
  return Vector3d::Zero();
}

Vector3d DirichletGroup::target_acceleration(const Vector3d& X, double s, double ds_dt) const {
  if (spec.kind != DirichletKind::rotation) return Vector3d::Zero();
  const Vector3d omega = ds_dt * spec.angle * spec.axis.normalized();
  return omega.cross(omega.cross(target_position(X, s) - moment_center));
}

std::vector<DirichletGroup> resolve_dirichlet_groups(const std::vector<DirichletSpec>& specs,
                                                     ConstRef<MatrixX3d> rest_positions,
                                                     double tolerance) {
  const Index num_vertices = rest_positions.rows();
  std::vector<std::vector<int>> selections;
  VectorXi owner = VectorXi::Constant(num_vertices, -1);
  for (size_t g = 0; g < specs.size(); ++g) {
    const DirichletSpec& spec = specs[g];
    validate_region(spec.region, spec.name + ".region");
    validate_amplitude(spec.amplitude, spec.name + ".amplitude");
    if (spec.kind == DirichletKind::rotation &&
        (!spec.axis.allFinite() || spec.axis.norm() == 0.0 || !std::isfinite(spec.angle)))
      throw InputError(spec.name + ": rotation needs a finite non-zero axis and a finite angle");
    if (!spec.components[0] && !spec.components[1] && !spec.components[2])
      throw InputError(spec.name + ": no component is prescribed");
    if (spec.kind == DirichletKind::displacement && !spec.displacement.allFinite())
      throw InputError(spec.name + ": displacement must be finite");
    selections.push_back(select_vertices(spec.region, rest_positions, tolerance));
    if (selections.back().empty()) throw InputError(spec.name + ": region selects no vertex");
    for (int v : selections.back())
      owner[v] = static_cast<int>(g);
  }
  std::vector<DirichletGroup> groups(specs.size());
  for (size_t g = 0; g < specs.size(); ++g) {
    DirichletGroup& group = groups[g];
    group.spec = specs[g];
    for (int v : selections[g])
      if (owner[v] == static_cast<int>(g)) group.vertices.push_back(v);
    if (group.vertices.empty())
      throw InputError(specs[g].name +
                       ": region selects no vertex that a later group leaves to it");
    if (specs[g].kind == DirichletKind::rotation && specs[g].has_center) {
      group.moment_center = specs[g].center;
    } else {
      Vector3d sum = Vector3d::Zero();
      for (int v : group.vertices)
        sum += rest_positions.row(v).transpose();
      group.moment_center = sum / static_cast<double>(group.vertices.size());
    }
  }
  return groups;
}

VectorXi dirichlet_owner(const std::vector<DirichletGroup>& groups, Index num_vertices) {
  VectorXi owner = VectorXi::Constant(num_vertices, -1);
  for (size_t g = 0; g < groups.size(); ++g)
    for (int v : groups[g].vertices)
      owner[v] = static_cast<int>(g);
  return owner;
}

std::vector<char> dirichlet_dof_mask(const std::vector<DirichletGroup>& groups,
                                     Index num_vertices) {
  std::vector<char> mask(3 * num_vertices, 0);
  for (const DirichletGroup& group : groups)
    for (int v : group.vertices)
      for (int c = 0; c < 3; ++c)
        mask[3 * v + c] = group.spec.components[c] ? 1 : 0;
  return mask;
}

int free_rigid_motions(const std::vector<DirichletGroup>& groups, ConstRef<VectorXd> rest) {
  // A rigid velocity t + ω × (X − c) keeps a prescribed coordinate k still when
  // t_k + (ω × r)_k = 0, r = (X − c) / L. Each such coordinate adds the row a with a·(t, ω) = 0 to
  // the Gram matrix Σ aᵀa; its null space is the motions left free.
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::max());
  Vector3d hi = -lo;
  Vector3d center = Vector3d::Zero();
  Index count = 0;
  for (const DirichletGroup& group : groups)
    for (int v : group.vertices) {
      const Vector3d X = rest.segment<3>(3 * v);
      lo = lo.cwiseMin(X);
      hi = hi.cwiseMax(X);
      center += X;
      ++count;
    }
  if (count == 0) return 6;
  center /= static_cast<double>(count);
  const double length = std::max((hi - lo).norm(), std::numeric_limits<double>::min());
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  for (const DirichletGroup& group : groups)
    for (int v : group.vertices) {
      const Vector3d r = (rest.segment<3>(3 * v) - center) / length;
      for (int k = 0; k < 3; ++k) {
        if (!group.spec.components[k]) continue;
        Eigen::Matrix<double, 6, 1> a = Eigen::Matrix<double, 6, 1>::Zero();
        a(k) = 1.0;
        // (ω × r)_k = ω · (r × e_k)
        a.tail<3>() = r.cross(Vector3d::Unit(k));
        gram += a * a.transpose();
      }
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(gram);
  const double largest = eigen.eigenvalues().maxCoeff();
  int free = 0;
  for (int i = 0; i < 6; ++i)
    free += eigen.eigenvalues()(i) <= 1e-10 * largest ? 1 : 0;
  return free;
}

void apply_dirichlet(const std::vector<DirichletGroup>& groups, ConstRef<VectorXd> rest, double t,
                     double default_s, double default_rate, VectorXd& x, VectorXd& v) {
  for (const DirichletGroup& group : groups) {
    const double s = group.factor(t, default_s);
    const double ds_dt = group.factor_rate(t, default_rate);
    for (int vertex : group.vertices) {
      const Vector3d X = rest.segment<3>(3 * vertex);
      const Vector3d target_x = group.target_position(X, s);
      const Vector3d target_v = group.target_velocity(X, s, ds_dt);
      for (int c = 0; c < 3; ++c) {
        if (!group.spec.components[c]) continue;
        x[3 * vertex + c] = target_x[c];
        v[3 * vertex + c] = target_v[c];
      }
    }
  }
}

}  // namespace strata
