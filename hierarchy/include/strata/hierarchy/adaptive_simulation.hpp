#pragma once
/// \file adaptive_simulation.hpp
/// The multiresolution driver: a core Simulation on an active cut of the refinement tree, with the
/// cut chosen by a mode —
///   - full:     every node at the tree's deepest level (the reference resolution);
///   - uniform:  every node at one level k;
///   - adaptive: starting at level k, refined where the criteria ask (refinement_controller.hpp)
///               and coarsened where children's stresses agree;
///   - precomputed: the cuts of a schedule recorded from earlier runs (precomputed_cut.hpp),
///               switched at the windows' starts, with no run-time criteria —
/// all through the same code path: flatten the cut (tree_flatten.hpp), build its hanging-vertex
/// embedding x = C q (hanging_constraints.hpp), and run core's Simulation on q with every
/// integrator and the static solver unchanged (SimulationOptions). A scene therefore means the same
/// thing on every cut: loads, fixed and prescribed regions and probes are defined on the finest
/// level (finest_level.hpp).
///
/// Lifecycle of an adaptive step (dynamic runs: every `adapt_every` steps; static runs: after
/// every load step, up to `max_passes` solve–mark–refine passes per load step, re-solving the same
/// load factor on the new cut):
///   advance the Simulation → CutState (positions, stresses, loads) → controller.decide → drop
///   coarsenings that would make a Dirichlet group inexact → controller.apply (cut edits) →
///   flatten + constraints of the new cut → carry positions and velocities through the tree's
///   vertices (cut_transfer.hpp: new vertices take the parent's linear field, so no energy jump on
///   refinement) → release coarsened subtrees (memory follows the active cut) → a new Simulation
///   that continues the clock (first_step) from the transferred state.
///
/// Full resolution when the cut is nearly full: when a refinement leaves the cut holding more
/// than HierarchySettings::full_resolution_fraction of the finest level's tets, every node goes to
/// the deepest level (the same transfer as any refinement) and the run goes on there without
/// estimates or cut changes (ToleranceReport::full_resolution_step).
///
/// Explicit integrators: refinement of a node is refused (vetoed) when the stable-step bound of
/// its children (any selection of them as one group, stable_time_step.hpp) falls below the scene's
/// dt; the time step is never changed, so outputs stay on the scene's time grid. Past
/// full_resolution_fraction()'s share they go on at full resolution, and the tets in contact are
/// refined to the finest level in the step they touch. If exact fixed/prescribed regions need
/// such a level, the construction throws InputError (reduce dt or use implicit Euler); 2:1 balance
/// is refused with explicit integrators. Implicit integrators and static runs refine freely.
///
/// Fixed and prescribed regions stay exact: before the run, active tets on which a group is not
/// exact are refined until it is, and such parents are never coarsened into (finest_level.hpp).
///
/// Energy at transfers: kinetic + elastic energy and momentum just before and just after each cut
/// change are recorded (`changes()`). Refinement keeps the elastic energy exactly (the new vertices
/// lie on the old linear field); coarsening loses the elastic energy of the fine detail the parent
/// cannot represent. Velocities: lumped masses of one linear field differ between cuts, so within
/// the changed region the velocities' deviation from the region's mean is rescaled and the mean
/// shifted to keep ½ Σ m v² and the momentum exactly; when prescribed vertices took over mass from
/// the region (coarser cuts lump more mass onto them), both cannot hold and the kinetic energy is
/// kept with the momentum's direction (a cut change never adds kinetic energy).
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_set>
#include <vector>

#include "strata/core/sim/simulation.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/finest_level.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"
#include "strata/hierarchy/precomputed_cut.hpp"
#include "strata/hierarchy/refinement_controller.hpp"
#include "strata/hierarchy/refinement_recovery_estimator.hpp"
#include "strata/hierarchy/tree_point_location.hpp"

namespace strata {

enum class HierarchyMode { full, uniform, adaptive, precomputed };

/// "full" / "uniform" / "adaptive" / "precomputed".
std::string to_string(HierarchyMode mode);

/// Settings of the hierarchy (scene key "hierarchy").
struct HierarchySettings {
  int levels = 1;                                ///< L: red-refinement levels below the coarse mesh
  HierarchyMode mode = HierarchyMode::adaptive;  ///<
  int level = 0;         ///< uniform: the level k; adaptive: the starting level
  int adapt_every = 10;  ///< dynamic: steps between two coarsening evaluations
  /// Refinement passes per step (≥ 1): static, solve–mark–refine per load step; dynamic, redos of
  /// a step on a refined cut; and the passes of the initial adaptation.
  int max_passes = 4;
  /// Refinement criterion, a name in refinement_indicator_registry(): "recovery" (the error
  /// estimate, refinement_recovery_estimator.hpp), "force" or "stress_jump".
  std::string indicator = "recovery";
  /// τ ∈ (0, 1): the relative displacement error against full resolution the run may have; the
  /// recovery indicator's threshold follows from it (refine where a tet's estimated error exceeds
  /// its equidistributed share of τ), and no refinement happens while the estimate is below τ.
  double tolerance = 0.01;
  /// Dynamic runs: before the first step, adapt the cut to the static response to the loads and
  /// prescribed motions at full load (solve–mark–refine, `max_passes`), then start from rest.
  bool initial_adaptation = true;
  /// Dynamic runs: test each step's result and redo the step on the refined cut (from the
  /// start-of-step state) where the criteria fail; false: refine every `adapt_every` steps.
  bool in_step_refinement = true;
  /// Adaptive runs: when a refinement leaves the cut holding more than this fraction of the
  /// finest level's tets, the run continues at full resolution (every node at the deepest level,
  /// no more estimates or cut changes): a cut that large costs more than full resolution (hanging
  /// vertices, estimates, redone steps and cut changes; README, "Error control"). 1: never.
  /// Not with an element budget below the finest level, max_level below the tree's depth, or an
  /// explicit integrator whose dt exceeds the finest level's stable-step estimate. Explicit
  /// integrators take at most AdaptiveSimulation::full_resolution_fraction()'s share.
  double full_resolution_fraction = 0.75;
  /// With the recovery estimate (an error-estimating indicator): the merges of one change are
  /// kept to those whose predicted estimate stays within coarsen_budget · tolerance
  /// (merges_within_budget), so that coarsening alone does not lift the run over its tolerance;
  /// and a dynamic run's in-step refinement, triggered by an estimate over the tolerance, marks
  /// against coarsen_budget · tolerance, so that an estimate that creeps up does not trip the
  /// test again a few steps later; ∈ (0, 1].
  double coarsen_budget = 0.8;
  /// With obstacles and no `contact_surface`: the finest level's boundary vertices
  /// (finest_boundary_points), embedded in each cut, are the contact points in place of the cut's
  /// boundary vertices (which are among them), so that an obstacle pressing between the vertices
  /// of a coarse cut is felt there. false: the cut's boundary vertices only. Not in mode full,
  /// whose boundary vertices are those points.
  bool finest_contact_points = true;
  /// `criteria.refine_threshold` was given explicitly (an expert override of the tolerance rule).
  bool refine_threshold_set = false;
  RefinementSettings criteria;  ///< thresholds and hysteresis
  /// Mode precomputed: the schedule of cuts to play back (validated against the coarse mesh).
  std::shared_ptr<const PrecomputedCut> precomputed;
};

/// Throws InputError naming `where` ("hierarchy") and the key for invalid settings: levels ∉ 0..8,
/// level ∉ 0..levels, adapt_every < 1, max_passes < 1, an unknown indicator, tolerance ∉ (0, 1),
/// invalid criteria, mode precomputed without a cut.
void validate_hierarchy_settings(const HierarchySettings& settings, const std::string& where);

/// One change of the active cut.
/// Wall time of the parts of one cut change [s]; they add up to its `seconds`.
struct CutChangePhases {
  double edit = 0.0;     ///< the controller's edit of the cut (and the cut kept in case it fails)
  double flatten = 0.0;  ///< flattened cut, hanging-vertex constraints, nested spaces, mapped loads
  double elastic_model = 0.0;  ///< the new Simulation's parts (SimulationBuildSeconds) …
  double reduced_model = 0.0;
  double problem = 0.0;  ///< … with the driver's load and gravity vectors
  double stepper = 0.0;
  double transfer = 0.0;  ///< positions, velocities, plastic state, kinetic energy, contact
  double records = 0.0;   ///< energies before and after
};

struct CutChangeRecord {
  /// After this step (static: load step; a static run's merges are made after a load step, on
  /// its equilibrium, before the next one is solved) …
  long step = 0;
  int pass = 0;                           ///< … and this pass (static; 0 in dynamic runs)
  double time = 0.0;                      ///< simulated time or load factor
  Index refined = 0;                      ///< nodes refined (including 2:1 balance)
  Index coarsened = 0;                    ///< parents coarsened
  Index tets_before = 0, tets_after = 0;  ///< active tets
  Index dofs_after = 0;                   ///< 3·#free vertices after the change
  double energy_before = 0.0;             ///< kinetic + elastic energy just before the change [J]
  double energy_after = 0.0;              ///< … just after (state transferred) [J]
  Vector3d momentum_before = Vector3d::Zero();  ///< Σ m_q v_q just before the change [kg·m/s]
  Vector3d momentum_after = Vector3d::Zero();   ///< … just after
  double seconds = 0.0;    ///< wall time of the change (edit, flatten, rebuild, transfer, records)
  CutChangePhases phases;  ///< … by part
  /// Multigrid hierarchies built on the cut this change made (the first by the solve after the
  /// change: Galerkin products, smoothers, coarse factor; more where the solver found them
  /// stale) and their wall time [s]. Not in `seconds`: the steps on the cut include them.
  long multigrid_setups = 0;
  double multigrid_setup_seconds = 0.0;
  /// Of those, the setups that kept the previous cut's coarse levels (the new cut's coarse spaces
  /// were the same) and set up only the finest level.
  long multigrid_carried_setups = 0;
  /// Plastic materials: largest |ε̄ₚ(child) − ε̄ₚ(parent)| over the merges of this change (the
  /// detail a merge averages away; 0 without merges or plasticity).
  double plastic_merge_change = 0.0;
  /// Obstacles: the largest move of a DOF vertex that took the transferred state out of the
  /// obstacles (AdaptiveSimulation, "Contact") [m]; 0 when it was feasible.
  double contact_correction = 0.0;
};

/// The active cut after a step.
struct CutSample {
  long step = 0;
  double time = 0.0;  ///< simulated time or load factor
  Index tets = 0;     ///< active tets
  Index dofs = 0;     ///< 3·#free vertices
  Index hanging = 0;  ///< hanging vertices
  /// Estimated relative displacement error against full resolution after the step
  /// (refinement_recovery_estimator.hpp), times the run's estimate scale (a measured static
  /// scale; with an explicit integrator, also kExplicitOvershoot).
  double estimated_error = 0.0;
  /// Relative energy-norm error against the exact solution (the estimate's raw form).
  double estimated_energy_error = 0.0;
  /// The two brackets of estimated_error (RecoveryEstimate): the upper estimate z and the
  /// relative error of the load's work c.
  double estimated_upper_error = 0.0;
  double estimated_load_work_error = 0.0;
  /// The local estimate ℓ (refinement_recovery_estimator.hpp).
  double estimated_local_error = 0.0;
};

/// How the run kept its tolerance.
struct ToleranceReport {
  double tolerance = 0.0;
  double max_estimated_error = 0.0;  ///< largest estimate over the accepted steps
  long steps_over_tolerance = 0;     ///< accepted steps whose estimate exceeded the tolerance
  /// Refinements the criteria asked for but could not make (max_level, element budget, explicit
  /// step veto, hysteresis) over the run.
  long refused_refinements = 0;
  long redone_steps = 0;  ///< redo passes: dynamic steps redone on a refined cut
  /// Accepted steps (static: load steps) whose every pass of hierarchy.max_passes refined, so that
  /// the last attempt was not judged again.
  long steps_out_of_passes = 0;
  /// Decisions over the tolerance on a cut none of whose tets may refine (every one at max_level
  /// or, with an explicit integrator, past the stable step limit): refinement is not asked for.
  long steps_unrefinable = 0;
  long calibration_passes = 0;         ///< static: passes made to measure a grown estimate again
  double redo_seconds = 0.0;           ///< wall time of the discarded attempts [s]
  int initial_refinements = 0;         ///< nodes refined by the initial adaptation
  int initial_passes = 0;              ///< static solves of the initial adaptation
  long initial_newton_iterations = 0;  ///< Newton iterations of those solves
  double initial_adaptation_seconds = 0.0;
  /// When the run went on at full resolution (HierarchySettings::full_resolution_fraction), or
  /// −1: 0 before the first step; a dynamic run redid step n + 1 at full resolution (n here) or
  /// changed after step n; a static run solved load step n again at full resolution.
  long full_resolution_step = -1;
  /// Static runs: the largest factor the estimate was scaled by (AdaptiveSimulation: a
  /// refinement pass that changed the solution more than the estimate of the cut it refined);
  /// 1 when none did.
  double estimate_scale = 1.0;
};

class AdaptiveSimulation final : public SimulationRun {
 public:
  /// `coarse`: the roots (validated and oriented by the caller, as for Simulation). The region
  /// loads of `problem` are applied on the finest level; its gravity, Dirichlet groups and ground
  /// and the solver settings as in Simulation. Contact: `problem.obstacles` are contacted by every
  /// active cut's boundary vertices, hanging ones included, and by the material points
  /// `contact_surface` (e.g. a fine surface's vertices, located in their roots), embedded in each
  /// cut's active tets — so fine detail collides even on a coarse cut. Without a
  /// `contact_surface` the finest level's boundary vertices take the place of both
  /// (HierarchySettings::finest_contact_points). The barrier stiffness is
  /// the same on every cut: E × the coarse mesh's mean edge length / 2^levels. Contact forces are
  /// loads for the criteria (CutState::external_forces), a parent is not coarsened while a
  /// contact force acts on its region, and a state carried to a new cut is pushed out of the
  /// obstacles where a contact point on the old field lies deeper than 0.9 d̂ inside one, to
  /// 0.8 d̂ (Simulation::push_out_of_obstacles, CutChangeRecord::contact_correction). Throws
  /// InputError for invalid settings or scene data.
  AdaptiveSimulation(const TetMesh& coarse, const HierarchySettings& hierarchy, ProblemSpec problem,
                     const SolverSettings& settings, std::vector<RootPoint> contact_surface = {});
  ~AdaptiveSimulation() override;
  AdaptiveSimulation(const AdaptiveSimulation&) = delete;
  AdaptiveSimulation& operator=(const AdaptiveSimulation&) = delete;

  /// One time step (or load step), then the criteria if due. Throws DivergenceError as Simulation.
  void advance() override;
  bool finished() const override { return live().finished(); }
  /// The Simulation on the current cut.
  const Simulation& current() const override { return live(); }
  double time() const { return live().time(); }
  long step_count() const { return live().step_count(); }

  /// The Simulation on the current cut (mesh = flat().mesh; rebuilt at every cut change).
  const Simulation& simulation() const { return live(); }
  const TetTree& tree() const { return *m_tree; }
  const ActiveCut& cut() const { return *m_cut; }
  /// The current cut as a mesh, with its tree maps.
  const FlatTreeMesh& flat() const { return m_constrained->flat; }
  const HangingConstraints& constraints() const { return m_constrained->constraints; }
  /// The share of the finest level's tets past which a refinement takes the run to full
  /// resolution: HierarchySettings::full_resolution_fraction, and with an explicit integrator at
  /// most f / (f + kExplicitEstimateCost) for its f force evaluations per step (1/5 symplectic
  /// Euler, 1/2 RK4): past it an adaptive step costs more than a step at full resolution.
  double full_resolution_fraction() const;
  /// What an explicit run's per-step decision (strains, recovered strains, the estimate's terms)
  /// costs per active tet, in internal-force evaluations per tet: 3–6 measured on 2k–16k-tet cuts
  /// of the project's scenes (README, "Error control").
  static constexpr double kExplicitEstimateCost = 4.0;
  /// Tree level of each active tet (#T of flat().mesh).
  VectorXi cell_levels() const;
  const HierarchySettings& settings() const { return m_settings; }
  const RefinementController& controller() const { return *m_controller; }

  /// Material points at rest positions `points` (n × 3), each located in its root (the nearest
  /// root within `tolerance` [m] for points just outside); throws InputError naming the point
  /// (`where`.i) if a point is farther than `tolerance` from the coarse mesh.
  std::vector<RootPoint> locate(ConstRef<MatrixX3d> points, const std::string& where,
                                double tolerance) const;
  /// Displacements (n × 3) of material points on the current cut, interpolated in the active
  /// ancestor of the leaf that contains each.
  MatrixX3d displacements(const std::vector<RootPoint>& points) const;

  /// Every cut change so far, and the cut after every step (plus the initial cut as step 0).
  const std::vector<CutChangeRecord>& changes() const { return m_changes; }
  const std::vector<CutSample>& history() const { return m_history; }
  /// Work summed over every Simulation of the run.
  SimulationCounters counters() const override;
  /// Wall time spent in cut changes (bookkeeping) and in Simulation::advance [s].
  double bookkeeping_seconds() const { return m_bookkeeping_seconds; }
  double stepping_seconds() const { return m_stepping_seconds; }
  /// The tolerance, the estimates and the redo counts of the run.
  const ToleranceReport& tolerance_report() const { return m_report; }
  /// Mode precomputed: the window of the schedule in use.
  std::size_t precomputed_window() const { return m_window; }
  /// Obstacles: whether the finest level's boundary vertices are the contact points
  /// (HierarchySettings::finest_contact_points).
  bool finest_contact_points() const { return m_finest_contact; }
  /// Obstacles: the largest depth of any contact point inside an obstacle over the accepted
  /// steps [m], the contact pairs after each accepted step, and the barrier stiffness [N/m].
  double max_penetration() const { return m_max_penetration; }
  const std::vector<Index>& contact_counts() const { return m_contact_counts; }
  double contact_stiffness() const { return m_contact_stiffness; }

 private:
  void make_dirichlet_exact();
  /// Flattens the cut (m_constrained) and maps the finest-level loads onto it (m_load_traction);
  /// returns the options of a Simulation on it that starts at `first_step`.
  SimulationOptions flatten(long first_step);
  /// flatten() and a new Simulation on the cut, its multigrid seeded with `smoother_estimates`
  /// and offered `coarse_levels` (SimulationOptions); m_mesh_external follows. Returns the
  /// flattening's seconds.
  double rebuild(long first_step, std::vector<SmootherEstimate> smoother_estimates = {},
                 std::shared_ptr<MultigridCoarseLevels> coarse_levels = {});
  /// *m_simulation; throws std::logic_error when a failed cut change left none.
  const Simulation& live() const;
  /// One decision and its cut change; a positive `calibration_target` refines against it instead
  /// of the tolerance (a calibration pass).
  bool adapt(int pass, bool refine, bool coarsen, double calibration_target = 0.0);
  /// Changes the cut by `changes` and moves the mesh-level state (x, v) of the current cut, with
  /// its kinetic energy, momentum and per-tet plastic state, onto it; the new Simulation starts at
  /// `first_step`. The current Simulation is released before the new one is built, so the state
  /// is taken by value.
  void change_cut(const CutChanges& changes, int pass, long first_step, VectorXd x, VectorXd v,
                  double old_kinetic_energy, const Vector3d& old_momentum, PlasticState plastic);
  CutChanges decide(bool refine, bool coarsen, double calibration_target = 0.0);
  void advance_with_redo();
  void initial_adaptation();
  /// Mode precomputed: changes the cut to window `w` of the schedule (before the first step:
  /// `initial`, no state to carry).
  void move_to_window(std::size_t w, bool initial);
  std::size_t m_window = 0;
  /// The estimate of the current state; raises the run's energy scale to its energy norm.
  const RecoveryEstimate& estimate_error();
  int max_refine_level() const;  ///< the deepest level refinement may reach
  bool children_stable(NodeId n) const;
  /// Whether an active tet of the cut may refine: below max_refine_level() and, with an explicit
  /// integrator, with children_stable(); computed once per cut.
  bool cut_can_refine() const;
  mutable std::optional<bool> m_cut_can_refine;
  /// The rest geometry the error estimate reads (recovery_geometry), computed once per cut.
  const RecoveryGeometry* cut_geometry();
  std::optional<RecoveryGeometry> m_cut_geometry;
  /// The bound on ω² of the children of a tet at `parent` (Bey-ordered positions) that `children`
  /// selects (bit k: child slot k), assembled as one group (stable_time_step.hpp); 0: the largest
  /// over every non-empty selection, which is the largest single child's. Kept by the parent's
  /// shape (its edges' squared lengths relative to the longest, to 2⁻⁴⁰; ω² scales as the inverse
  /// square of the size), with a relative margin of 1e-9 for shapes that share a key: the tree's
  /// tets fall into a few shapes (Bey's refinement makes at most three similarity classes per
  /// root), so the bound of a whole level costs a few eigen-solves.
  double sibling_frequency_squared(const Matrix3x4d& parent, std::uint8_t children) const;
  /// Per parent shape: ω² × the longest squared edge, per selection of children (NaN: not yet
  /// computed; entry 0: the largest over the selections).
  mutable std::map<std::array<std::int64_t, 6>, std::array<double, 256>> m_sibling_frequencies;
  /// Explicit integrators: the active tets in contact (m_in_contact, as criteria_loads found it)
  /// below the deepest level whose children are stable, within max_active_elements: refined at
  /// once, the estimate aside. Their parents are not merged meanwhile (the coarsening veto holds
  /// nodes in contact).
  std::vector<NodeId> explicit_contact_refinements() const;
  /// The bound on ω_max of the current cut: its tets grouped by parent, a root on its own.
  double cut_max_angular_frequency() const;
  /// Static runs after a refinement pass re-solved its load step, and a dynamic run's initial
  /// adaptation after its calibration pass: the pass's change (largest vertex displacement
  /// difference between the carried state `carried` and the new equilibrium `solved`, relative
  /// to the largest displacement) bounds the refined cut's error from
  /// below; where it exceeds that cut's estimate `refined_estimate`, their ratio scales the
  /// estimate of every later decision and sample (m_estimate_scale; the latest measurement
  /// stands, 1 when it is within the estimate).
  void measure_estimate(double refined_estimate, const VectorXd& solved, const VectorXd& carried);
  double m_estimate_scale = 1.0;
  /// The factor on the estimate of the run's decisions, samples and initial adaptation:
  /// m_estimate_scale, times kExplicitOvershoot with an explicit integrator.
  double estimate_scale() const;
  /// Explicit integrators add no numerical damping (nor does material damping lower the factor).
  /// The error a coarse cut commits under a residual that appears suddenly (an impact, a load
  /// switched on) then overshoots the estimate of the state, which reads that residual as if it
  /// were static, by up to the dynamic load factor of an undamped oscillator under a step load, 2
  /// (backward Euler damps the overshoot at the project's step sizes).
  static constexpr double kExplicitOvershoot = 2.0;
  /// Static runs: each active tet's share of the estimate (η_t,full² / ‖u‖_E², per flat tet) on
  /// the cut a load step's passes ended on, or on a cut no pass has measured yet; empty after a
  /// cut change. When the shares that grew since then add up to more than (kCalibrationGrowth² − 1)
  /// of their total, on a later load step within the tolerance, the run makes one calibration
  /// pass: refinement against kCalibrationFraction of its estimate, re-solved and measured like
  /// any pass (a load that starts late, or grows elsewhere than the passes saw, changes how far
  /// the estimate reads the error). A load step within the tolerance before any pass has
  /// measured the estimate makes one as well.
  VectorXd m_calibrated_shares;
  bool m_estimate_measured = false;  ///< whether a pass has measured the estimate (static runs)
  static constexpr double kCalibrationGrowth = 1.25;
  static constexpr double kCalibrationFraction = 0.5;
  /// Estimates below this fraction of the tolerance (scaled) are not measured again.
  static constexpr double kCalibrationFloor = 0.1;
  static VectorXd error_shares(const RecoveryEstimate& estimate);
  bool calibration_due() const;
  /// Explicit integrators: whether solver.dt is within the stable-step estimate of the tree's
  /// finest level (computed once), so that the run may go on at full resolution.
  bool finest_level_stable() const;
  mutable std::optional<bool> m_finest_level_stable;
  /// A cut change threw: the run cannot go on (the Simulation, if any, is the previous cut's,
  /// rebuilt at the state the change was moving).
  bool m_failed = false;
  /// The run went on at full resolution (full_resolution_fraction): the cut is every node at the
  /// deepest level and no longer adapts.
  bool m_at_full_resolution = false;
  /// Whether the run adapts its cut now (mode adaptive, not yet at full resolution).
  bool adapting() const;
  /// Whether the cut holds more than full_resolution_fraction of the finest level's tets and the
  /// run may go on at full resolution.
  bool past_full_resolution_fraction() const;
  /// Makes the cut every node at the deepest level; the nodes it refined.
  Index edit_to_full_resolution();
  void record_sample();
  /// One step of advance() (which keeps the change records' setups on failure too).
  void advance_step();
  /// The multigrid setups of m_simulation so far into the change record that built it.
  void note_solver_setups();
  /// Obstacles: the contact record of the step just accepted (before a coarsening rebuilds the
  /// Simulation).
  void record_contact_step();
  void keep_kinetic_energy(const FlatTreeMesh& old_flat, const HangingConstraints& old_constraints,
                           const VectorXd& old_dof_mass, double old_kinetic_energy,
                           const Vector3d& old_momentum);

  HierarchySettings m_settings;
  /// The indicator is an error estimate (refinement_indicator_registry.hpp).
  bool m_estimates_error = false;
  /// Whether the controller's decision in progress may merge (its merge filter reads it).
  bool m_decision_merges = true;
  Material m_material;
  std::vector<DirichletSpec> m_dirichlet;
  std::optional<GroundPlane> m_ground;
  Vector3d m_gravity;
  SolverSettings m_solver;
  double m_tolerance = 0.0;

  std::unique_ptr<TetTree> m_tree;
  std::unique_ptr<ActiveCut> m_cut;
  std::unique_ptr<TreePointLocator> m_locator;
  std::unique_ptr<RefinementController> m_controller;
  std::vector<Obstacle> m_obstacles;
  std::vector<RootPoint> m_contact_surface;
  /// m_contact_surface holds the finest level's boundary vertices (in place of each cut's).
  bool m_finest_contact = false;
  double m_contact_stiffness = 0.0;
  double m_max_penetration = 0.0;
  std::vector<Index> m_contact_counts;
  /// Active nodes a contact force acts on, and their ancestors (not coarsened into).
  std::unordered_set<NodeId> m_in_contact;
  /// The scene's problem for a Simulation on the current cut, with `dirichlet` as its groups and
  /// without its region loads (mapped from the finest level into SimulationOptions).
  ProblemSpec cut_problem(std::vector<DirichletSpec> dirichlet) const;
  /// Contact points and barrier stiffness of the current cut into `options`.
  void add_contact(SimulationOptions& options) const;
  /// The external loads the criteria see: m_mesh_external plus the contact forces (updating
  /// m_in_contact).
  VectorXd criteria_loads(const Simulation& simulation);
  /// Static runs with obstacles, during a load step's passes: the state at the start of the load
  /// step (mesh positions of the current cut, carried with each change), from which friction in
  /// a re-solve measures slip; empty otherwise.
  VectorXd m_load_step_start;
  /// Whether a load or a prescribed motion with an amplitude grows before a merge made now could
  /// be undone: its largest magnitude over the next max(adapt_every, min_steps_between_changes)
  /// steps (dynamic) or max(1, min_steps_between_changes) load steps (static) exceeds its
  /// magnitude now.
  bool load_grows_before_next_decision() const;
  /// Whether a load or a prescribed motion with an amplitude grows at any later time of the run:
  /// its largest magnitude after now exceeds its magnitude now.
  bool load_grows_later() const;
  /// Whether a load or a prescribed motion with an amplitude rises beyond its magnitude now
  /// before `until` (time, or load factor in static runs).
  bool load_grows_until(double until) const;
  /// Whether `test` holds for the amplitude of a load, or of a prescribed motion (fixed groups
  /// do not move; groups on the run's default ramp grow in proportion from the start).
  template <typename Test>
  bool any_timed_amplitude(Test&& test) const {
    for (const auto& [amplitude, point_loads] : m_timed_point_loads)
      if (test(amplitude)) return true;
    for (const DirichletSpec& group : m_dirichlet)
      if (group.kind != DirichletKind::fixed && !group.amplitude.empty() && test(group.amplitude))
        return true;
    return false;
  }
  /// Dynamic runs: the cut the initial adaptation chose for the static response at the loads'
  /// peaks, as the nodes it refined (each by its root and its path of child slots, which outlive
  /// the node ids a merge frees). While a load with an amplitude still grows later, no merge
  /// makes the cut coarser than it: a pulse that comes back, or a load that starts late, then
  /// meets the cut its peak needs. On a cut coarser than that (the roots) the estimate of a
  /// load's first steps sees too little of it to refine in time.
  std::set<std::pair<int, std::uint64_t>> m_load_floor;
  /// children_stable() of the nodes asked so far, by node_path (written from const calls: serial
  /// callers only, as the refinement controller's are).
  mutable std::map<std::pair<int, std::uint64_t>, bool> m_children_stable;
  /// Whether the decision in progress keeps the cut at least as fine as m_load_floor.
  bool m_hold_load_floor = false;
  std::pair<int, std::uint64_t> node_path(NodeId n) const;
  std::vector<PointLoad> m_point_loads;  ///< of the loads without an amplitude
  /// Loads with an amplitude, each on the finest level.
  std::vector<std::pair<Amplitude, std::vector<PointLoad>>> m_timed_point_loads;
  std::unique_ptr<ConstrainedCut> m_constrained;
  VectorXd m_mesh_external;  ///< 3·#V of the current cut: gravity + mapped point loads
  VectorXd m_load_traction;  ///< #T of the current cut: largest finest-level load traction
  std::unique_ptr<Simulation> m_simulation;

  std::vector<CutChangeRecord> m_changes;
  /// The change record whose cut m_simulation was built on; −1 for another rebuild.
  std::ptrdiff_t m_simulation_change = -1;
  std::vector<CutSample> m_history;
  SimulationCounters m_finished_counters;  ///< of the Simulations already replaced
  double m_bookkeeping_seconds = 0.0;
  double m_stepping_seconds = 0.0;
  ToleranceReport m_report;
  double m_energy_scale = 0.0;  ///< largest ‖u‖_E² of the accepted steps so far [J]
  /// E × volume × stress_floor²: the smallest ‖u‖_E² an estimate is relative to [J].
  double m_energy_floor = 0.0;
  /// The largest vertex displacement of the accepted steps so far, and its floor (stress_floor
  /// strain across the body's diagonal): what the local estimate is relative to [m].
  double m_displacement_scale = 0.0;
  double m_displacement_floor = 0.0;
  RecoveryEstimate m_estimate;  ///< of the current state while m_estimate_valid
  bool m_estimate_valid = false;
};

}  // namespace strata
