#pragma once
/// \file simulation_run.hpp
/// What a driver of a whole run offers its caller, for a plain run on one mesh (Simulation) and a
/// multiresolution run on a changing active cut (AdaptiveSimulation, strata::hierarchy) alike:
/// step until finished, read the state of the current mesh, count the work.
namespace strata {

class Simulation;
struct SimulationCounters;

class SimulationRun {
 public:
  virtual ~SimulationRun() = default;
  /// One time step or load step, with whatever the driver does around it (cut changes, redos).
  /// Throws DivergenceError if the run diverges.
  virtual void advance() = 0;
  virtual bool finished() const = 0;
  /// The Simulation on the current mesh: the run itself for a plain run, the active cut's for a
  /// hierarchy (replaced when the cut changes, so do not keep the reference across advance()).
  virtual const Simulation& current() const = 0;
  /// Work over the whole run.
  virtual SimulationCounters counters() const = 0;
};

}  // namespace strata
