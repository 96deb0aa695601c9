#pragma once
/// \file time_stepper.hpp
/// One interface for every way a run advances: static load stepping, backward Euler, symplectic
/// Euler and RK4. A stepper advances the DOF state (q, v) of a Problem over one step [t₀, t₁] —
/// time in seconds for the dynamic steppers, the load factor for static load stepping — and
/// reports Newton's result (implicit steppers) or a converged result without iterations
/// (explicit ones). The registry (`stepper_registry`) lists every stepper with its traits; adding
/// one touches its own file and one registration in stepper_registry.cpp.
#include <memory>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/linear_solver.hpp"
#include "strata/core/sim/newton_solver.hpp"
#include "strata/core/sim/problem.hpp"
#include "strata/core/sim/solver_settings.hpp"

namespace strata {

class TimeStepper {
 public:
  virtual ~TimeStepper() = default;
  /// Advances (q, v) (3·#Q each) from t₀ to t₁ = t₀ + h; h is passed as given (the scene's dt
  /// exactly, not t₁ − t₀ with its round-off). On a result that did not converge, q and v are left
  /// at the start of the step.
  virtual NewtonResult step(double t0, double t1, double h, VectorXd& q, VectorXd& v) = 0;
  /// Re-solves the state at t (static load stepping after the state moved to a new cut); other
  /// steppers throw std::logic_error. `contact_reference` (3·#Q, or empty: q): the state friction
  /// measures slip from, the start of the load step carried to the new cut.
  virtual NewtonResult resolve(double t, VectorXd& q, VectorXd& v,
                               const VectorXd& contact_reference);
  /// The state was replaced (initial state, a new cut, a new plastic state): no step history
  /// carries over.
  virtual void reset_history() {}
  /// Called with the accepted state q after a step when the next step follows and the run checks
  /// for inverted tets: a stepper whose next step starts with the internal forces at q may compute
  /// them now, keep them for that step, and return the smallest volume ratio det F over the tets
  /// (with its tet) from the same pass; others return nothing and the check makes its own pass.
  virtual std::optional<std::pair<double, Index>> prepare_next_step(const VectorXd&) {
    return std::nullopt;
  }
  /// The linear solver of implicit steppers; nullptr for explicit ones.
  virtual const SpdSolver* linear_solver() const { return nullptr; }
  virtual SpdSolver* linear_solver() { return nullptr; }
  /// The energy Newton minimises (implicit steppers); nullptr for explicit ones.
  virtual const EnergySum* energy() const { return nullptr; }
};

/// A registered stepper.
struct StepperTraits {
  std::string_view name;  ///< "static" | "implicit_euler" | "symplectic_euler" | "rk4"
  SimulationMode mode;    ///< static load stepping or time integration
  Integrator integrator;  ///< dynamic steppers: the scene's solver.integrator
  bool is_explicit;       ///< conditionally stable (dt below the stable estimate)
  /// Explicit steppers: internal-force evaluations per step (1 symplectic Euler, 4 RK4); 0 for
  /// the implicit ones, whose Newton iterations vary.
  int force_evaluations;
  std::unique_ptr<TimeStepper> (*make)(const Problem& problem, const SolverSettings& settings);
};

/// Every stepper strata has.
const std::vector<StepperTraits>& stepper_registry();
/// The stepper a run with `settings` uses (static mode ignores the integrator).
const StepperTraits& find_stepper(const SolverSettings& settings);

}  // namespace strata
