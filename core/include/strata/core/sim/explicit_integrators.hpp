#pragma once
/// \file explicit_integrators.hpp
/// Explicit time steps of the Problem. Both are conditionally stable: dt must stay below
/// roughly the CFL estimate (stable_time_step.hpp); a violation blows up and is caught by
/// check_divergence. Dirichlet DOFs are set to their targets at the end of the step.
#include "strata/core/common/types.hpp"
#include "strata/core/sim/problem.hpp"

namespace strata {

/// Vectors an explicit step reuses from the previous one (no allocation per step).
struct ExplicitScratch {
  VectorXd forces;
  /// `forces` are the internal forces at the state the next step starts from (computed after the
  /// previous step, with the inversion check): that step uses them instead of evaluating them.
  bool forces_current = false;
};

/// Symplectic (semi-implicit) Euler from time t: v ← v + h a(x, v), then x ← x + h v.
/// One force evaluation per step; energy oscillates without secular drift. Without damping the
/// update is one parallel pass over the DOFs after the force evaluation.
void symplectic_euler_step(const Problem& system, double t, double h, VectorXd& x, VectorXd& v,
                           ExplicitScratch* scratch = nullptr);

/// Classical fourth-order Runge–Kutta on (x, v)' = (v, a(x, v)) from time t; the Dirichlet DOFs'
/// stage velocities and accelerations are the prescribed ones at each stage time.
void rk4_step(const Problem& system, double t, double h, VectorXd& x, VectorXd& v);

}  // namespace strata
