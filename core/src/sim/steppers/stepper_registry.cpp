#include <stdexcept>

#include "strata/core/common/error.hpp"
#include "strata/core/sim/steppers/dynamic_steppers.hpp"
#include "strata/core/sim/steppers/static_load_stepper.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"

namespace strata {

NewtonResult TimeStepper::resolve(double, VectorXd&, VectorXd&, const VectorXd&) {
  throw std::logic_error("TimeStepper::resolve: only static load stepping re-solves a step");
}

const std::vector<StepperTraits>& stepper_registry() {
  static const std::vector<StepperTraits> registry = {
      {"static", SimulationMode::static_equilibrium, Integrator::implicit_euler, false, 0,
       &make_static_load_stepper},
      {"implicit_euler", SimulationMode::dynamic, Integrator::implicit_euler, false, 0,
       &make_backward_euler_stepper},
      {"symplectic_euler", SimulationMode::dynamic, Integrator::symplectic_euler, true, 1,
       &make_symplectic_euler_stepper},
      {"rk4", SimulationMode::dynamic, Integrator::rk4, true, 4, &make_rk4_stepper},
  };
  return registry;
}

const StepperTraits& find_stepper(const SolverSettings& settings) {
  for (const StepperTraits& traits : stepper_registry()) {
    if (traits.mode != settings.mode) continue;
    if (traits.mode == SimulationMode::static_equilibrium ||
        traits.integrator == settings.integrator)
      return traits;
  }
  throw InputError("solver: no stepper for mode " + to_string(settings.mode) + " and integrator " +
                   to_string(settings.integrator));
}

}  // namespace strata
