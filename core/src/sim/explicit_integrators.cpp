#include "strata/core/sim/explicit_integrators.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace strata {

void symplectic_euler_step(const Problem& system, double t, double h, VectorXd& x, VectorXd& v,
                           ExplicitScratch* scratch) {
  if (system.mass_damping == 0.0 && system.stiffness_damping == 0.0) {
    // a = (f_int + f_ext) / m, v += h a, x += h v in one pass; the Dirichlet DOFs are set to their
    // targets afterwards (their accelerations do not matter).
    VectorXd local;
    VectorXd& f = scratch != nullptr ? scratch->forces : local;
    if (scratch == nullptr || !scratch->forces_current || f.size() != x.size())
      system.internal_forces(x, f);
    if (scratch != nullptr) scratch->forces_current = false;
    VectorXd timed_external;
    if (system.has_timed_forces()) system.external_forces_at(t, 1.0, timed_external);
    const double* f_ext =
        system.has_timed_forces() ? timed_external.data() : system.external_forces.data();
    const double* mass = system.dof_mass.data();
    double* xs = x.data();
    double* vs = v.data();
    const double* fs = f.data();
    tbb::parallel_for(tbb::blocked_range<Index>(0, x.size(), 16384),
                      [&](const tbb::blocked_range<Index>& range) {
                        for (Index i = range.begin(); i != range.end(); ++i) {
                          vs[i] += h * ((fs[i] + f_ext[i]) / mass[i]);
                          xs[i] += h * vs[i];
                        }
                      });
    system.apply_constraints(t + h, x, v);
    return;
  }
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
