#include "strata/core/sim/problem.hpp"

#include <algorithm>

#include "strata/core/common/error.hpp"
#include "strata/core/sim/linear_solver.hpp"

namespace strata {

void Problem::use_nested_spaces(SpdSolver& solver, const std::vector<Index>& free_dofs) const {
  solver.use_nested_spaces(
      nested_spaces, free_dofs,
      smoother_estimates != nullptr ? *smoother_estimates : std::vector<SmootherEstimate>{},
      coarse_levels != nullptr ? *coarse_levels : std::shared_ptr<MultigridCoarseLevels>{});
}

double Problem::ramp(double t) const {
  return std::clamp(t / ramp_time, 0.0, 1.0);
}

double Problem::ramp_rate(double t) const {
  return t < ramp_time ? 1.0 / ramp_time : 0.0;
}

void Problem::external_forces_at(double t, double base_scale, VectorXd& f) const {
  f = base_scale * external_forces;
  if (timed_forces == nullptr) return;
  for (const TimedForces& timed : *timed_forces)
    f += timed.amplitude.value(t) * timed.forces;
}

void Problem::apply_constraints(double t, VectorXd& x, VectorXd& v) const {
  apply_dirichlet(groups, model.rest_positions(), t, ramp(t), ramp_rate(t), x, v);
}

void Problem::add_damping_forces(const VectorXd& x, const VectorXd& v, const VectorXd& f_int,
                                 VectorXd& f) const {
  if (mass_damping > 0.0) f.array() -= mass_damping * dof_mass.array() * v.array();
  if (stiffness_damping <= 0.0) return;
  const double speed = v.lpNorm<Eigen::Infinity>();
  if (speed == 0.0) return;
  const double epsilon = 1e-7 * diagonal / speed;
  VectorXd f_shifted;
  const VectorXd x_shifted = x + epsilon * v;
  model.forces(x_shifted, f_shifted);
  // −β K v = β (f_int(x + εv) − f_int(x)) / ε
  f += (stiffness_damping / epsilon) * (f_shifted - f_int);
}

void Problem::internal_forces(const VectorXd& x, VectorXd& f_int) const {
  model.forces(x, f_int);
  if (springs != nullptr) springs->add_forces(x, f_int);
}

std::pair<double, Index> Problem::internal_forces_and_min_volume_ratio(const VectorXd& x,
                                                                       VectorXd& f_int) const {
  STRATA_VERIFY(model.is_identity(),
                "Problem::internal_forces_and_min_volume_ratio needs the mesh's own DOFs");
  const std::pair<double, Index> smallest =
      model.mesh_model().forces_and_min_volume_ratio(x, f_int);
  if (springs != nullptr) springs->add_forces(x, f_int);
  return smallest;
}

void Problem::accelerations(double t, const VectorXd& x, const VectorXd& v, VectorXd& a) const {
  VectorXd f_int;
  model.forces(x, f_int);  // the damping's finite difference differentiates these
  VectorXd f = f_int;
  if (springs != nullptr) springs->add_forces(x, f);
  if (has_timed_forces()) {
    VectorXd f_ext;
    external_forces_at(t, 1.0, f_ext);
    f += f_ext;
  } else {
    f += external_forces;
  }
  add_damping_forces(x, v, f_int, f);
  a = f.array() / dof_mass.array();
  const VectorXd& rest = model.rest_positions();
  for (const DirichletGroup& group : groups) {
    const double s = group.factor(t, ramp(t));
    const double ds_dt = group.factor_rate(t, ramp_rate(t));
    for (int vertex : group.vertices) {
      const Vector3d target = group.target_acceleration(rest.segment<3>(3 * vertex), s, ds_dt);
      for (int c = 0; c < 3; ++c)
        if (group.spec.components[c]) a[3 * vertex + c] = target[c];
    }
  }
}

}  // namespace strata
