#include "strata/core/sim/implicit_euler.hpp"

namespace strata {

ImplicitEuler::ImplicitEuler(const DynamicsSystem& system, LinearSolverKind solver,
                             int max_newton_iterations, double newton_tolerance)
    : m_system(system),
      m_solver(solver),
      m_reduction(system.model.stiffness_pattern(), system.constrained),
      m_max_iterations(max_newton_iterations),
      m_tolerance(newton_tolerance) {}

NewtonResult ImplicitEuler::step(double t, double h, VectorXd& x, VectorXd& v) {
  const DynamicsSystem& sys = m_system;
  const EmbeddedElasticModel& model = sys.model;
  const VectorXd& M = sys.dof_mass;
  const double alpha = sys.mass_damping;
  const double beta = sys.stiffness_damping;
  const VectorXd x_start = x;
  const VectorXd x_tilde = x + h * v;
  if (beta > 0.0) model.stiffness(x_start, m_damping_stiffness, true);

  // Mass-like diagonal weight: 1/h² (inertia) + α/h (mass damping).
  const VectorXd diagonal = M * (1.0 / (h * h) + alpha / h);
  auto energy = [&](const VectorXd& y) {
    const VectorXd dx = y - x_tilde;
    const VectorXd dn = y - x_start;
    double e = 0.5 / (h * h) * dx.dot(M.cwiseProduct(dx)) + model.energy(y) -
               sys.external_forces.dot(y) + 0.5 * alpha / h * dn.dot(M.cwiseProduct(dn));
    if (beta > 0.0) e += 0.5 * beta / h * dn.dot(m_damping_stiffness * dn);
    return e;
  };
  auto gradient = [&](const VectorXd& y, VectorXd& g) {
    VectorXd f_int;
    model.forces(y, f_int);
    const VectorXd dn = y - x_start;
    g = M.cwiseProduct(y - x_tilde) / (h * h) - f_int - sys.external_forces +
        (alpha / h) * M.cwiseProduct(dn);
    if (beta > 0.0) g += (beta / h) * (m_damping_stiffness * dn);
  };
  auto hessian = [&](const VectorXd& y, SparseMatrixd& H) {
    model.stiffness(y, H, true);
    if (beta > 0.0) {
      Eigen::Map<VectorXd> values(H.valuePtr(), H.nonZeros());
      values += (beta / h) * Eigen::Map<const VectorXd>(m_damping_stiffness.valuePtr(),
                                                        m_damping_stiffness.nonZeros());
    }
    for (Index i = 0; i < H.rows(); ++i)
      H.coeffRef(i, i) += diagonal[i];
  };

  VectorXd y = x_tilde;
  VectorXd v_end = v;
  sys.apply_constraints(t + h, y, v_end);

  VectorXd f_int;
  model.forces(y, f_int);
  NewtonSettings settings;
  settings.max_iterations = m_max_iterations;
  settings.tolerance = m_tolerance;
  settings.force_scale = M.cwiseProduct(y - x_tilde).norm() / (h * h) + f_int.norm() +
                         sys.external_forces.norm() + M.cwiseProduct(v).norm() / h;
  settings.step_tolerance = 1e-13 * sys.diagonal;
  settings.residual_floor = internal_force_roundoff(model);
  const LameParameters lame = model.material().lame();
  settings.energy_scale = (2 * lame.mu + lame.lambda) * model.total_rest_volume() +
                          std::abs(sys.external_forces.dot(y)) +
                          0.5 / (h * h) * (y - x_tilde).dot(M.cwiseProduct(y - x_tilde));

  const NewtonResult result =
      newton_minimize({energy, gradient, hessian}, m_reduction, m_solver, settings, y);
  v = (y - x_start) / h;
  x = y;
  // Dirichlet velocities are the prescribed ones, not the difference quotient.
  sys.apply_constraints(t + h, x, v);
  return result;
}

}  // namespace strata
