#pragma once
/// \file simulation.hpp
/// The simulation driver: owns the elastic model, constraints, loads and contact (bound into a
/// Problem) and the stepper the settings select (steppers/time_stepper.hpp), and advances one time
/// step (dynamic) or one load step (static) per call. A library class: no I/O.
///
/// Lifecycle: construct (validates, selects regions, precomputes masses, loads and the stable step
/// estimate) → set_state (optional initial velocity / shape) → while (!finished()) advance() →
/// query positions, energies, reactions and counters at any point.
///
/// Embedding (optional, SimulationOptions): the mesh's vertices may be a linear function of fewer
/// DOF vertices, x = (C ⊗ I₃) q (embedded_model.hpp) — the hanging vertices of an active cut of
/// the refinement tree. The state, masses (m_q = Cᵀ m), loads (f_q = Cᵀ f), Dirichlet groups
/// (resolved on the DOF vertices' rest positions), contact and reactions then live on q; every
/// integrator and the static solver run unchanged. `positions()`/`velocities()` always return the
/// mesh's 3·#V vectors (x = P q), `dof_positions()`/`dof_velocities()` the 3·#Q state. Without an
/// embedding q = x and both coincide.
///
/// Reactions: for each Dirichlet group, the force the constraint exerts on the body,
///   R = Σ_{i ∈ group} (m_i a_i − f_int,i − f_ext,i − f_damp,i − f_contact,i),
/// with a_i the prescribed acceleration (zero in static mode, f_ext scaled by the load factor
/// there), and its moment Σ (x_i − c) × R_i about the group's moment center c with the current
/// positions as lever arms.
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/plasticity.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/divergence_check.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/energy/contact_term.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/multigrid.hpp"
#include "strata/core/sim/obstacle.hpp"
#include "strata/core/sim/problem_spec.hpp"
#include "strata/core/sim/simulation_run.hpp"
#include "strata/core/sim/solver_settings.hpp"
#include "strata/core/sim/surface_springs.hpp"

namespace strata {

struct Problem;
struct NewtonResult;
struct StepperTraits;
class TimeStepper;

/// Reaction of one Dirichlet group.
struct GroupReaction {
  std::string name;
  Vector3d force = Vector3d::Zero();          ///< [N], exerted by the constraint on the body
  Vector3d moment = Vector3d::Zero();         ///< [N·m] about moment_center
  Vector3d moment_center = Vector3d::Zero();  ///< [m]
};

/// Wall time of the parts of a Simulation's construction [s].
struct SimulationBuildSeconds {
  double elastic_model = 0.0;  ///< rest data and element schedule of the mesh (ElasticModel)
  double reduced_model = 0.0;  ///< the model on the DOF vertices: patterns, assembly plan
  double problem = 0.0;        ///< masses, Dirichlet groups, loads, contact points
  double stepper = 0.0;        ///< the time stepper: DOF reduction, energy terms, solver transfers
};

/// Optional construction parameters, for drivers that rebuild the simulation on a new mesh
/// mid-run (the adaptive hierarchy).
struct SimulationOptions {
  /// x = (C ⊗ I₃) q: C (#V × #Q, rows sum to 1, non-negative) and the mesh vertex of each DOF
  /// vertex (identity rows). Empty `dof_vertices`: no embedding (q = x).
  SparseMatrixd vertex_embedding;
  std::vector<int> dof_vertices;
  /// Dead loads on the mesh vertices (3·#V [N]) added to gravity and the region loads, e.g. loads
  /// defined on a finer mesh and mapped onto this one; empty for none.
  VectorXd extra_mesh_forces;
  /// Mesh-vertex loads that follow their own amplitude (3·#V each), added to those of the region
  /// loads with an amplitude.
  std::vector<TimedForces> extra_timed_mesh_forces;
  /// Step index the run starts from: time() = (first_step + steps taken) · dt in dynamic mode,
  /// load factor (first_step + steps taken) / load_steps in static mode, and the Dirichlet ramp
  /// continues from there.
  long first_step = 0;
  /// Coarser spaces below the DOF vertices for the multigrid linear solver (the refinement tree's
  /// levels, hierarchy/cut_levels.hpp); empty: none.
  NestedSpaces nested_spaces;
  /// The smoother estimates of a multigrid hierarchy on a nearby system (the previous cut:
  /// Simulation::smoother_estimates) for the first setup on `nested_spaces`; empty: measured.
  std::vector<SmootherEstimate> smoother_estimates;
  /// The coarse levels of that hierarchy (Simulation::release_coarse_levels), taken by the first
  /// setup on `nested_spaces` where its coarse spaces are the same (SpdSolver::use_nested_spaces);
  /// null: computed.
  std::shared_ptr<MultigridCoarseLevels> coarse_levels;
  /// Plastic state per mesh tet to start from (material with plasticity only); empty: virgin
  /// material (Fₚ = I, ε̄ₚ = 0).
  PlasticState plastic_state;
  /// Surface springs with yielding rest lengths (surface_springs.hpp) on the mesh's boundary
  /// edges; meshes without an embedding only.
  std::optional<SurfaceSpringSettings> surface_springs;
  /// Further contact points for ProblemSpec::obstacles as weighted mesh vertices (e.g. the
  /// vertices of a bound fine surface, through their barycentric weights): the barrier and
  /// friction act on them too and their forces reach the DOFs through the weights. With an
  /// embedding a hanging boundary vertex is tested where its constraint puts it.
  std::vector<ContactPoint> contact_points;
  /// Whether every boundary vertex is a contact point (before `contact_points`). A driver whose
  /// `contact_points` already hold the boundary vertices (the hierarchy's finest-level boundary
  /// points) sets false.
  bool boundary_contact_points = true;
  /// Barrier stiffness κ [N/m] of the obstacles; 0: E × this mesh's mean edge length. A driver
  /// that runs one scene on several meshes (the hierarchy's cuts) fixes it for all of them.
  double contact_stiffness = 0.0;
  /// A bound on the highest angular frequency of the system linearised at rest [rad/s] that the
  /// driver computed, for stable_dt_estimate: over groups of tets (stable_time_step.hpp), e.g.
  /// the hierarchy's sibling tets or a box mesh's cells; 0: the element bound of this mesh.
  double max_angular_frequency = 0.0;
};

/// Work counters of this Simulation object (not including steps before `first_step`).
struct SimulationCounters {
  long steps = 0;                     ///< time or load steps taken
  long newton_iterations = 0;         ///< over all implicit / static steps
  long long element_evaluations = 0;  ///< from ElasticModel
  long factorizations = 0;            ///< numeric factorisations (or CG setups)
  long linear_iterations = 0;         ///< CG iterations (incl. those on a previous factor)
  long reused_factor_solves = 0;      ///< linear solves answered without a new factorisation
  long multigrid_setups = 0;          ///< multigrid hierarchies built (multigrid only)
  /// of which set up only their finest level on a previous hierarchy's coarse levels
  long multigrid_carried_setups = 0;
  double multigrid_setup_seconds = 0.0;  ///< their wall time [s]
  long multigrid_direct_fallbacks = 0;   ///< multigrid solves finished by CHOLMOD
  /// Linear solver of the Newton steps (automatic resolved; over several cuts, that of the
  /// current one); cholmod for explicit runs.
  LinearSolverKind linear_solver = LinearSolverKind::cholmod;
  long exact_hessian_iterations = 0;      ///< Newton iterations on the exact Hessian
  long shifted_hessian_iterations = 0;    ///< … on the exact Hessian plus a multiple of I
  long projected_hessian_iterations = 0;  ///< … on the PSD-projected Hessian
  /// Newton solves (time or load steps) that converged on the increment, and that stopped at a
  /// residual stalled (newton_solver.hpp); both are converged.
  long increment_converged_steps = 0;
  long stalled_steps = 0;
  /// Largest final ‖residual‖ / residual target over the Newton solves (≤ 1 unless a solve
  /// converged on the increment or stalled).
  double max_residual_ratio = 0.0;
  /// Plasticity: return mappings done (one per explicit step; one per solve of an implicit or
  /// static step), steps whose passes ended before the plastic tolerance was met, and the tets
  /// that flowed in the last step.
  long plastic_passes = 0;
  long plastic_unconverged_steps = 0;
  Index yielded_tets = 0;
};

class Simulation final : public SimulationRun {
 public:
  /// `mesh` must be validated and positively oriented (validate_tet_mesh, orient_tets).
  /// Throws InputError for a vertex without tets, invalid material / settings / regions / ground,
  /// an empty Dirichlet group or load region, or static mode without any Dirichlet group.
  Simulation(TetMesh mesh, ProblemSpec problem, const SolverSettings& settings,
             SimulationOptions options = {});
  ~Simulation() override;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Replaces the DOF state (3·#Q each, = 3·#V without an embedding; e.g. an initial velocity);
  /// Dirichlet DOFs are reset to their targets at the current time. Throws InputError on a size
  /// mismatch or non-finite values.
  void set_state(ConstRef<VectorXd> positions, ConstRef<VectorXd> velocities);

  /// One time step of `dt` (dynamic) or one load step (static). Throws DivergenceError naming the
  /// step and time (or load factor) if the state diverges or Newton fails; std::logic_error if
  /// called when finished().
  void advance() override;
  /// Static mode only: re-solves the equilibrium at the current load factor, starting from the
  /// current state (e.g. after a driver carried the state over to a new mesh with
  /// SimulationOptions::first_step = the step just taken). The step count is unchanged; the next
  /// load step starts from this solution without extrapolation. Throws DivergenceError as
  /// advance(); std::logic_error in dynamic mode or before the first load step. With obstacles,
  /// `contact_reference` (3·#Q; empty: the current state) is the state friction measures slip
  /// from: the start of the load step, carried to this mesh.
  void resolve_static(const VectorXd& contact_reference = VectorXd());
  /// Dynamic: t ≥ duration (up to 10⁻⁹ dt; the last step is not shortened, so the run takes
  /// ⌈duration/dt⌉ steps). Static: all load_steps done.
  bool finished() const override;

  /// Mesh positions x = P q, 3·#V [m].
  const VectorXd& positions() const { return m_embedded->is_identity() ? m_x : m_mesh_x; }
  /// Mesh velocities P v_q, 3·#V [m/s] (zero in static mode).
  const VectorXd& velocities() const { return m_embedded->is_identity() ? m_v : m_mesh_v; }
  const VectorXd& dof_positions() const { return m_x; }   ///< q, 3·#Q [m]
  const VectorXd& dof_velocities() const { return m_v; }  ///< 3·#Q [m/s]
  /// Dynamic: simulated time [s]; static: the load factor k/N.
  double time() const;
  /// Dirichlet ramp / load factor s ∈ [0, 1] of the current state.
  double load_factor() const;
  /// Absolute step index (first_step + steps taken).
  long step_count() const { return m_steps; }

  /// Largest stable step of the chosen integrator [s], a guaranteed bound for the problem
  /// linearised at rest (stable_time_step.hpp): from SimulationOptions::max_angular_frequency,
  /// or the element bound; reported, never applied. Computed on first use.
  double stable_dt_estimate() const;

  std::vector<GroupReaction> reactions() const;
  double kinetic_energy() const;  ///< ½ v_qᵀ M_q v_q [J]
  /// Ψ(x) [J], with the surface springs' energy if there are any.
  double elastic_energy() const;
  /// The surface springs, or nullptr.
  const SurfaceSprings* surface_springs() const { return m_springs.get(); }
  /// Potential of the dead loads −s_f f_extᵀ(x − X) [J] (s_f = load factor in static mode, 1 in
  /// dynamic mode); with loads that follow amplitudes, that of the loads acting now,
  /// −f_ext(t)ᵀ(x − X).
  double external_potential_energy() const;
  SimulationCounters counters() const override;
  /// The smoother estimates of the tree multigrid's last setup (empty without one), for a
  /// Simulation built next on a nearby system (SimulationOptions::smoother_estimates).
  std::vector<SmootherEstimate> smoother_estimates() const;
  /// The coarse levels of the tree multigrid's last setup, given up for a Simulation built next
  /// on a nearby system (SimulationOptions::coarse_levels); this one sets up anew at its next
  /// solve. Null without them (SpdSolver::release_coarse_levels).
  std::shared_ptr<MultigridCoarseLevels> release_coarse_levels();
  /// A plain run is its own current simulation.
  const Simulation& current() const override { return *this; }

  const TetMesh& mesh() const { return m_mesh; }
  const ElasticModel& model() const { return *m_model; }  ///< on the mesh (3·#V)
  /// Where the construction's time went.
  const SimulationBuildSeconds& build_seconds() const { return m_build_seconds; }
  /// The model on the DOFs (x = P q).
  const EmbeddedElasticModel& embedded_model() const { return *m_embedded; }
  const SolverSettings& settings() const { return m_settings; }
  /// Groups with DOF-vertex indices (= mesh vertices without an embedding).
  const std::vector<DirichletGroup>& dirichlet_groups() const { return m_groups; }
  const MatrixX3i& boundary() const;  ///< boundary triangles #F × 3 (found on first use)
  const VectorXd& vertex_mass() const { return m_vertex_mass; }  ///< mesh, #V [kg]
  /// Lumped masses of the DOF vertices, Cᵀ m (#Q) [kg].
  const VectorXd& dof_vertex_mass() const { return m_dof_vertex_mass; }
  /// Full (unscaled) external force vector of the loads without an amplitude on the DOFs,
  /// 3·#Q [N].
  const VectorXd& external_forces() const { return m_external; }
  /// The loads with an amplitude on the DOFs (3·#Q each).
  const std::vector<TimedForces>& timed_forces() const { return m_timed; }
  /// External forces acting on the DOFs in the current state, 3·#Q [N]: at the load factor in
  /// static runs, at the current time in dynamic ones.
  VectorXd current_external_forces() const;
  const DivergenceLimits& divergence_limits() const { return m_limits; }
  /// Obstacle contact: the settings (tolerance d̂, barrier stiffness κ = E × mean edge length,
  /// friction slip), the largest depth of a contact point inside an obstacle after any step so
  /// far [m], the point–obstacle pairs in contact after each step, and the contact forces the
  /// obstacles exert now (3·#Q [N], normal and friction). Explicit integrators, which project
  /// the DOF vertices out of the obstacles after each step, report the vertex–obstacle pairs
  /// projected in it, the depth the deepest vertex had reached, and as contact forces the
  /// momentum the projection changed over the step, M Δv / h: forces of the last step, zero
  /// after a state set from outside (set_state, a new cut) until the next step.
  bool has_obstacles() const { return !m_obstacles.empty(); }
  const ContactSettings& contact_settings() const;
  double max_penetration() const { return m_max_penetration; }
  /// Points tested for contact (the boundary vertices unless SimulationOptions says otherwise,
  /// then SimulationOptions::contact_points).
  Index contact_points() const { return static_cast<Index>(m_contact_points.size()); }
  /// Of those, the SimulationOptions::contact_points.
  Index extra_contact_points() const { return m_extra_contact_points; }
  const std::vector<Index>& contact_counts() const { return m_contact_counts; }
  /// Depth of the deepest contact point inside an obstacle after the last step [m] (≤ 0 when
  /// none is inside; 0 before the first step).
  double last_penetration() const { return m_last_penetration; }
  VectorXd contact_forces() const;
  /// The barrier's (normal) contact forces at the current state on the mesh vertices, 3·#V [N]
  /// (explicit integrators: the projection's, contact_forces(), at the DOF vertices):
  /// each contact point's force spread over its mesh vertices by its weights (hanging vertices
  /// keep their share; a driver reads them as loads). Zero without obstacles.
  VectorXd mesh_contact_forces() const;
  /// The contact force (normal and friction) on each SimulationOptions::contact_points entry, in
  /// their order [N]; empty without obstacles.
  std::vector<Vector3d> surface_contact_forces() const;
  /// Moves free DOF vertices so that no contact point lies deeper than `depth` × the contact
  /// tolerance inside an obstacle at the current time (each deeper point is pushed out along ∇φ
  /// to `to_depth` × the tolerance inside, 0: to the surface, its correction shared over its DOF
  /// vertices by weight, repeated up to 20 times). For a state carried over from another mesh (a
  /// cut change near curved obstacles, where new vertices on the old linear field can lie
  /// inside). Returns the largest correction of a DOF vertex [m] (0 when the state was feasible);
  /// velocities are unchanged.
  double push_out_of_obstacles(double depth = 0.5, double to_depth = 0.0);
  /// Whether the material is plastic.
  bool is_plastic() const { return m_material.plasticity.has_value(); }
  /// Plastic state per mesh tet (empty unless is_plastic()).
  const PlasticState& plastic_state() const { return m_plastic; }
  /// Replaces the plastic state (#T entries; e.g. carried over from another cut). Throws
  /// InputError for a material without plasticity or a size mismatch.
  void set_plastic_state(PlasticState state);

 private:
  void update_mesh_state();
  /// Return mapping after a step from t0 to t1 (step h) whose start state was (q, v); implicit and
  /// static steps are repeated with the updated state until it settles.
  void update_plastic_state(double t0, double t1, double h, const VectorXd& q_start,
                            const VectorXd& v_start);
  bool is_static() const;
  [[noreturn]] void throw_newton_failure(const std::string& context,
                                         const NewtonResult& result) const;
  /// " after N iterations (gradient norm …), stopped at <why>" and held_contact(t), for a Newton
  /// solve that did not converge at time (static: load factor) t.
  std::string newton_failure_detail(const NewtonResult& result, double t) const;
  /// With obstacles: "; <obstacle> has reached a point held by <group> …" for the first contact
  /// point whose weighted DOF vertices Dirichlet groups hold all of and that lies at least the
  /// contact distance d̂ inside an obstacle at time (static: load factor) t, where its barrier is
  /// infinite and no step can lower it; "" otherwise.
  std::string held_contact(double t) const;

  TetMesh m_mesh;
  Material m_material;
  SolverSettings m_settings;
  SimulationBuildSeconds m_build_seconds;
  std::unique_ptr<ElasticModel> m_model;
  std::unique_ptr<EmbeddedElasticModel> m_embedded;
  mutable std::once_flag m_boundary_once;  ///< boundary() may be first called from any thread
  mutable MatrixX3i m_boundary;
  VectorXd m_vertex_mass;
  VectorXd m_dof_vertex_mass;
  VectorXd m_dof_mass;
  VectorXd m_external;
  std::vector<TimedForces> m_timed;
  std::vector<DirichletGroup> m_groups;
  std::vector<char> m_constrained;
  std::optional<GroundPlane> m_ground;
  double m_ground_stiffness = 0.0;
  double m_diagonal = 0.0;
  mutable std::once_flag m_stable_dt_once;
  mutable double m_stable_dt = 0.0;
  double m_max_angular_frequency = 0.0;  ///< SimulationOptions::max_angular_frequency
  DivergenceLimits m_limits;
  NestedSpaces m_nested;
  std::vector<SmootherEstimate> m_smoother_seed;  ///< SimulationOptions::smoother_estimates
  /// SimulationOptions::coarse_levels, until the stepper's solver has them.
  std::shared_ptr<MultigridCoarseLevels> m_coarse_seed;
  std::unique_ptr<Problem> m_system;
  const StepperTraits* m_stepper_traits = nullptr;
  std::unique_ptr<TimeStepper> m_stepper;

  VectorXd m_x;
  VectorXd m_v;
  VectorXd m_mesh_x;  ///< P q (only with an embedding)
  VectorXd m_mesh_v;
  long m_first_step = 0;
  long m_steps = 0;
  PlasticState m_plastic;
  std::unique_ptr<SurfaceSprings> m_springs;
  std::vector<Obstacle> m_obstacles;
  std::vector<ContactPoint> m_contact_points;  ///< on the DOFs
  Index m_extra_contact_points = 0;
  /// Mesh-vertex contact points carried to the DOFs through the embedding's rows.
  std::vector<ContactPoint> embed_points(const std::vector<ContactPoint>& points) const;
  std::unique_ptr<ContactTerm> m_contact;  ///< mirrors the stepper's, lagged at the last step
  std::vector<ContactPoint> m_mesh_contact_points;  ///< the same points on mesh vertices
  double m_max_penetration = 0.0;
  double m_last_penetration = 0.0;
  long m_contact_step = -1;  ///< step index of the last contact record
  /// Explicit integrators: the last step's projection out of the obstacles, its contacts, the
  /// depth the deepest vertex had reached [m] and M Δv / h (3·#Q [N]).
  Index m_projected_contacts = 0;
  double m_projection_depth = 0.0;
  VectorXd m_projection_forces;
  std::vector<Index> m_contact_counts;
  void record_contact(const VectorXd& q_start, double t0, double t1);
  SimulationCounters m_newton;  ///< Newton and plasticity fields only
  void record_newton(const NewtonResult& result);
  /// Forgets the last explicit projection (a state set from outside has not been through it).
  void clear_projection();
};

}  // namespace strata
