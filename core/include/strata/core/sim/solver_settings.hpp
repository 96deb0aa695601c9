#pragma once
/// \file solver_settings.hpp
/// Run settings of a simulation: mode, integrator, step sizes, linear solver, Newton controls.
#include <string>

namespace strata {

/// dynamic: time integration; static_equilibrium: quasi-static load stepping ("static" in scenes).
enum class SimulationMode { dynamic, static_equilibrium };
enum class Integrator { symplectic_euler, rk4, implicit_euler };
/// cholmod: CHOLMOD supernodal Cholesky; cg: conjugate gradients with incomplete Cholesky;
/// multigrid: conjugate gradients preconditioned by a V-cycle over the refinement tree's levels
/// (multigrid.hpp; CHOLMOD where the mesh has no coarser levels); amg: conjugate gradients
/// preconditioned by algebraic multigrid (algebraic_multigrid.hpp, hypre's BoomerAMG); automatic:
/// multigrid on meshes with coarser levels and at least kMultigridMinDofs free DOFs, elsewhere
/// algebraic multigrid from kAlgebraicMultigridMinDofs free DOFs and CHOLMOD below.
enum class LinearSolverKind { cholmod, cg, multigrid, automatic, amg };

/// The Newton controls of one solve (StaticSolver, ImplicitEuler): what a scene's `solver` sets,
/// with the iteration limit resolved (newton_controls()).
struct NewtonControls {
  int max_iterations = 50;
  double tolerance = 1e-10;
  /// Exact Hessian where positive definite (else projected); false: always PSD-projected.
  bool exact_hessian = true;
};

/// The scene's `solver` block: how the run advances (mode, integrator, steps), then the settings
/// of the solves inside a step, of contact and of plasticity, each a group of its own. The scene
/// file keeps these keys flat under `solver` (README, "solver").
struct SolverSettings {
  SimulationMode mode = SimulationMode::dynamic;
  Integrator integrator = Integrator::implicit_euler;
  double dt = 1e-3;       ///< time step [s] (dynamic)
  double duration = 1.0;  ///< simulated time [s] (dynamic)
  /// Dirichlet ramp time [s] (dynamic): s = min(t / ramp_time, 1); 0 means `duration`.
  double ramp_time = 0.0;
  int load_steps = 10;  ///< N: load factor k/N at step k (static)

  /// Newton's solves of static and implicit steps, and their linear solver.
  struct Newton {
    LinearSolverKind linear_solver = LinearSolverKind::automatic;
    /// Per time or load step; 0: 50, or 200 when there are obstacles (contact solves approach
    /// the barrier in steps cut by its filter). Scene: solver.max_newton_iterations.
    int max_iterations = 0;
    /// Newton stops when ‖∇E‖ over the free DOFs ≤ tolerance × force scale (static: the applied
    /// external load, or the internal forces of the first guess when there is no load). Scene:
    /// solver.newton_tolerance.
    double tolerance = 1e-10;
    /// Exact where positive definite, else PSD-projected (true); or always projected (false).
    /// Scene: solver.hessian = "exact_where_pd" | "projected".
    bool exact_hessian = true;
  } newton;

  /// Ground and obstacle contact.
  struct Contact {
    /// Ground penalty stiffness factor (ProblemSpec::ground, static mode), see
    /// ground_penalty_stiffness. Library only: the scene's `ground` is an obstacle.
    double ground_stiffness_factor = 100.0;
    /// Obstacle contact (energy/contact_term.hpp): the tolerance d̂ [m], the deepest a vertex can
    /// enter an obstacle (0: 1e-3 × the bounding-box diagonal), and the friction slip ε [m] per
    /// step below which friction sticks (0: 1e-3 × d̂). Scene: solver.contact_distance,
    /// solver.friction_slip.
    double distance = 0.0;
    double friction_slip = 0.0;
  } contact;

  /// Plasticity (implicit and static steps): a step is repeated with the updated plastic state
  /// until no tet's ε̄ₚ changes by more than tolerance × σ_y / E between passes, at most
  /// max_passes solves per step (then the step is kept and counted as unconverged). Scene:
  /// solver.max_plastic_passes, solver.plastic_tolerance.
  struct Plasticity {
    int max_passes = 25;
    double tolerance = 1e-3;
  } plasticity;
};
std::string to_string(SimulationMode mode);    ///< "dynamic" | "static"
std::string to_string(Integrator integrator);  ///< "symplectic_euler" | "rk4" | "implicit_euler"
std::string to_string(LinearSolverKind kind);  ///< "cholmod" | "cg" | "multigrid" | "amg" | "auto"
/// Parsers for scene names; throw InputError listing the valid names.
SimulationMode simulation_mode_from_string(const std::string& name);
Integrator integrator_from_string(const std::string& name);
LinearSolverKind linear_solver_from_string(const std::string& name);

/// Newton's iteration limit per step: `newton.max_iterations`, or when it is 0, 50 (200 with
/// contact).
int newton_iteration_limit(const SolverSettings& settings, bool contact);

/// The Newton controls of a step's solve: the iteration limit (newton_iteration_limit), the
/// tolerance and the Hessian of `settings.newton`.
NewtonControls newton_controls(const SolverSettings& settings, bool contact);

/// The steps a run takes: load_steps (static), or ⌈duration / dt⌉ and at least one (dynamic; a
/// duration below dt takes one step).
long planned_steps(const SolverSettings& settings);

/// Throws InputError naming `where` (e.g. "solver") and the scene key unless dt > 0,
/// duration > 0, ramp_time ≥ 0, load_steps in [1, 1e6], newton.max_iterations ≥ 0,
/// newton.tolerance > 0, contact.ground_stiffness_factor > 0, contact.distance ≥ 0,
/// contact.friction_slip ≥ 0, plasticity.max_passes ≥ 1, plasticity.tolerance > 0 (all finite),
/// and a dynamic run takes at most 1e8 steps.
void validate_solver_settings(const SolverSettings& settings, const std::string& where);

}  // namespace strata
