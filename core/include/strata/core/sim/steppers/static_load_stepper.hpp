#pragma once
/// \file static_load_stepper.hpp
/// Quasi-static load stepping: each step solves the equilibrium at the load factor t₁
/// (static_solver.hpp), starting from the previous solution extrapolated linearly along the load
/// path (no extrapolation after a reset or a re-solve). Velocities stay zero.
#include "strata/core/sim/static_solver.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"

namespace strata {

class StaticLoadStepper final : public TimeStepper {
 public:
  StaticLoadStepper(const Problem& problem, const SolverSettings& settings);
  NewtonResult step(double t0, double t1, double h, VectorXd& q, VectorXd& v) override;
  NewtonResult resolve(double t, VectorXd& q, VectorXd& v,
                       const VectorXd& contact_reference) override;
  void reset_history() override { m_has_previous = false; }
  const SpdSolver* linear_solver() const override { return &m_solver.linear_solver(); }
  SpdSolver* linear_solver() override { return &m_solver.linear_solver(); }
  const EnergySum* energy() const override { return &m_solver.energy(); }

 private:
  const Problem& m_problem;
  StaticSolver m_solver;
  VectorXd m_previous;  ///< the solution before the last step
  bool m_has_previous = false;
};

std::unique_ptr<TimeStepper> make_static_load_stepper(const Problem& problem,
                                                      const SolverSettings& settings);

}  // namespace strata
