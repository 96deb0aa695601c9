#include "strata/core/sim/solver_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "strata/core/common/error.hpp"

namespace strata {

std::string to_string(SimulationMode mode) {
  return mode == SimulationMode::dynamic ? "dynamic" : "static";
}

std::string to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::symplectic_euler:
      return "symplectic_euler";
    case Integrator::rk4:
      return "rk4";
    case Integrator::implicit_euler:
      return "implicit_euler";
  }
  return "?";
}

std::string to_string(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::cholmod:
      return "cholmod";
    case LinearSolverKind::cg:
      return "cg";
    case LinearSolverKind::multigrid:
      return "multigrid";
    case LinearSolverKind::amg:
      return "amg";
    case LinearSolverKind::automatic:
      return "auto";
  }
  return "?";
}

SimulationMode simulation_mode_from_string(const std::string& name) {
  if (name == "dynamic") return SimulationMode::dynamic;
  if (name == "static") return SimulationMode::static_equilibrium;
  throw InputError("unknown mode '" + name + "' (valid: dynamic, static)");
}

Integrator integrator_from_string(const std::string& name) {
  if (name == "symplectic_euler") return Integrator::symplectic_euler;
  if (name == "rk4") return Integrator::rk4;
  if (name == "implicit_euler") return Integrator::implicit_euler;
  throw InputError("unknown integrator '" + name +
                   "' (valid: symplectic_euler, rk4, implicit_euler)");
}

LinearSolverKind linear_solver_from_string(const std::string& name) {
  if (name == "cholmod") return LinearSolverKind::cholmod;
  if (name == "cg") return LinearSolverKind::cg;
  if (name == "multigrid") return LinearSolverKind::multigrid;
  if (name == "amg") return LinearSolverKind::amg;
  if (name == "auto") return LinearSolverKind::automatic;
  throw InputError("unknown linear solver '" + name +
                   "' (valid: cholmod, cg, multigrid, amg, auto)");
}

int newton_iteration_limit(const SolverSettings& settings, bool contact) {
  if (settings.newton.max_iterations > 0) return settings.newton.max_iterations;
  return contact ? 200 : 50;
}

NewtonControls newton_controls(const SolverSettings& settings, bool contact) {
  return {newton_iteration_limit(settings, contact), settings.newton.tolerance,
          settings.newton.exact_hessian};
}

long planned_steps(const SolverSettings& settings) {
  if (settings.mode == SimulationMode::static_equilibrium) return settings.load_steps;
  return std::max(1L, static_cast<long>(std::ceil(settings.duration / settings.dt - 1e-9)));
}

void validate_solver_settings(const SolverSettings& s, const std::string& where) {
  auto positive = [&](double value, const char* key) {
    if (!std::isfinite(value) || value <= 0.0)
      throw InputError(where + "." + key + ": must be a finite number > 0");
  };
  positive(s.dt, "dt");
  positive(s.duration, "duration");
  positive(s.newton.tolerance, "newton_tolerance");
  positive(s.contact.ground_stiffness_factor, "contact_stiffness_factor");
  positive(s.plasticity.tolerance, "plastic_tolerance");
  if (!std::isfinite(s.contact.distance) || s.contact.distance < 0.0)
    throw InputError(where + ".contact_distance: must be a finite number >= 0");
  if (!std::isfinite(s.contact.friction_slip) || s.contact.friction_slip < 0.0)
    throw InputError(where + ".friction_slip: must be a finite number >= 0");
  if (!std::isfinite(s.ramp_time) || s.ramp_time < 0.0)
    throw InputError(where + ".ramp_time: must be a finite number >= 0");
  if (s.load_steps < 1) throw InputError(where + ".load_steps: must be >= 1");
  // Runs of more steps than these would not end in any reasonable time (a static load step
  // takes a Newton solve, a dynamic step at least microseconds).
  if (s.mode == SimulationMode::static_equilibrium && s.load_steps > 1000000)
    throw InputError(where + ".load_steps: must be at most 1e6");
  if (s.mode == SimulationMode::dynamic && s.duration / s.dt > 1e8) {
    char text[96];
    std::snprintf(text, sizeof(text), ".dt: duration / dt = %.3g steps (at most 1e8)",
                  s.duration / s.dt);
    throw InputError(where + text);
  }
  if (s.newton.max_iterations < 0)
    throw InputError(where + ".max_newton_iterations: must be >= 0 (0: automatic)");
  if (s.plasticity.max_passes < 1) throw InputError(where + ".max_plastic_passes: must be >= 1");
}

}  // namespace strata
