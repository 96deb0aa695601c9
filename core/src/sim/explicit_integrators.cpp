#include "strata/core/sim/explicit_integrators.hpp"

namespace strata {

void symplectic_euler_step(const Problem& system, double t, double h, VectorXd& x, VectorXd& v) {
  VectorXd a;
  system.accelerations(t, x, v, a);
  v += h * a;
  x += h * v;
  system.apply_constraints(t + h, x, v);
}

void rk4_step(const Problem& system, double t, double h, VectorXd& x, VectorXd& v) {
  // Stage states carry the prescribed motion at Dirichlet DOFs so stage velocities are exact.
  auto stage = [&](double time, VectorXd xs, VectorXd vs, VectorXd& dx, VectorXd& dv) {
    system.apply_constraints(time, xs, vs);
    dx = vs;
    system.accelerations(time, xs, vs, dv);
  };
  VectorXd k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;
  stage(t, x, v, k1x, k1v);
  stage(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v, k2x, k2v);
  stage(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v, k3x, k3v);
  stage(t + h, x + h * k3x, v + h * k3v, k4x, k4v);
  x += (h / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  v += (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  system.apply_constraints(t + h, x, v);
}

}  // namespace strata
