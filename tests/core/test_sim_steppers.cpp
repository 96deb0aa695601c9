// The stepper registry: every stepper is found from its settings, advances a free fall as the
// analytic solution says, and leaves the state at the start of the step when Newton fails.
#include <gtest/gtest.h>

#include <memory>
#include <set>
#include <string>

#include "problem_test_utils.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"

namespace strata {
namespace {

Material neohookean() {
  Material material;
  material.model = MaterialModel::neohookean;
  return material;
}

/// A free box under gravity, without constraints.
struct FreeBox : testing::BoxProblem {
  FreeBox()
      : BoxProblem(Vector3d(0.2, 0.1, 0.1), {2, 1, 1}, neohookean(), Vector3d(0, 0, -9.81), false) {
  }
};

TEST(Steppers, RegistryFindsEveryStepperByItsSettings) {
  std::set<std::string> names;
  for (const StepperTraits& traits : stepper_registry()) {
    names.insert(std::string(traits.name));
    SolverSettings settings;
    settings.mode = traits.mode;
    settings.integrator = traits.integrator;
    EXPECT_EQ(&find_stepper(settings), &traits) << traits.name;
    EXPECT_EQ(traits.is_explicit, traits.mode == SimulationMode::dynamic &&
                                      traits.integrator != Integrator::implicit_euler);
    if (traits.mode == SimulationMode::dynamic) {
      EXPECT_EQ(traits.name, to_string(traits.integrator));
    }
  }
  EXPECT_EQ(names, (std::set<std::string>{"static", "implicit_euler", "symplectic_euler", "rk4"}));
}

TEST(Steppers, DynamicSteppersFollowFreeFall) {
  const FreeBox box;
  const double h = 1e-3, g = 9.81;
  const int steps = 20;
  const double t = steps * h;
  for (const StepperTraits& traits : stepper_registry()) {
    if (traits.mode != SimulationMode::dynamic) continue;
    SolverSettings settings;
    settings.integrator = traits.integrator;
    std::unique_ptr<TimeStepper> stepper = traits.make(*box.problem, settings);
    VectorXd q = box.model->rest_positions();
    VectorXd v = VectorXd::Zero(q.size());
    for (int k = 0; k < steps; ++k) {
      const NewtonResult result = stepper->step(k * h, (k + 1) * h, h, q, v);
      ASSERT_TRUE(result.converged) << traits.name;
    }
    // Every vertex falls rigidly: Δz = −½ g t² up to the method's O(h) (exact for RK4).
    const double expected = -0.5 * g * t * t;
    const double tolerance = traits.integrator == Integrator::rk4 ? 1e-9 : 0.5 * g * t * h + 1e-12;
    for (Index i = 0; i < q.size() / 3; ++i) {
      EXPECT_NEAR(q[3 * i + 2] - box.mesh.vertices(i, 2), expected, tolerance) << traits.name;
      EXPECT_NEAR(v[3 * i + 2], -g * t, traits.integrator == Integrator::rk4 ? 1e-9 : 1e-6)
          << traits.name;
    }
  }
}

TEST(Steppers, FailedImplicitStepLeavesTheStartState) {
  const FreeBox box;
  SolverSettings settings;
  settings.newton.max_iterations = 1;
  settings.newton.tolerance = 1e-300;  // one iteration cannot reach it
  std::unique_ptr<TimeStepper> stepper = find_stepper(settings).make(*box.problem, settings);
  VectorXd q = box.model->rest_positions();
  q[0] += 0.01;  // a deformed start, so the step has work to do
  VectorXd v = VectorXd::Constant(q.size(), 0.3);
  const VectorXd q0 = q, v0 = v;
  const NewtonResult result = stepper->step(0.0, 1e-3, 1e-3, q, v);
  ASSERT_FALSE(result.converged);
  EXPECT_EQ(q, q0);
  EXPECT_EQ(v, v0);
}

}  // namespace
}  // namespace strata
