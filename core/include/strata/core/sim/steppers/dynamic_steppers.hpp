#pragma once
/// \file dynamic_steppers.hpp
/// The time integrators as steppers: backward Euler (implicit_euler.hpp), symplectic Euler and
/// RK4 (explicit_integrators.hpp).
#include "strata/core/sim/explicit_integrators.hpp"
#include "strata/core/sim/implicit_euler.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"

namespace strata {

class BackwardEulerStepper final : public TimeStepper {
 public:
  BackwardEulerStepper(const Problem& problem, const SolverSettings& settings);
  NewtonResult step(double t0, double t1, double h, VectorXd& q, VectorXd& v) override;
  const SpdSolver* linear_solver() const override { return &m_integrator.linear_solver(); }
  SpdSolver* linear_solver() override { return &m_integrator.linear_solver(); }
  const EnergySum* energy() const override { return &m_integrator.energy(); }

 private:
  ImplicitEuler m_integrator;
};

class SymplecticEulerStepper final : public TimeStepper {
 public:
  explicit SymplecticEulerStepper(const Problem& problem) : m_problem(problem) {}
  NewtonResult step(double t0, double t1, double h, VectorXd& q, VectorXd& v) override;
  void reset_history() override { m_scratch.forces_current = false; }
  /// Without damping (one force evaluation per step, at its start) and on the mesh's own DOFs.
  std::optional<std::pair<double, Index>> prepare_next_step(const VectorXd& q) override;

 private:
  const Problem& m_problem;
  ExplicitScratch m_scratch;
};

class Rk4Stepper final : public TimeStepper {
 public:
  explicit Rk4Stepper(const Problem& problem) : m_problem(problem) {}
  NewtonResult step(double t0, double t1, double h, VectorXd& q, VectorXd& v) override;

 private:
  const Problem& m_problem;
};

std::unique_ptr<TimeStepper> make_backward_euler_stepper(const Problem& problem,
                                                         const SolverSettings& settings);
std::unique_ptr<TimeStepper> make_symplectic_euler_stepper(const Problem& problem,
                                                           const SolverSettings& settings);
std::unique_ptr<TimeStepper> make_rk4_stepper(const Problem& problem,
                                              const SolverSettings& settings);

}  // namespace strata
