#include "strata/app/scene_runner.hpp"

#include "memory_check.hpp"

#include "spring_body_runner.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "strata/app/fine_surface.hpp"
#include "strata/app/huge_pages.hpp"
#include "strata/app/mesh_command.hpp"
#include "strata/app/progress_bar.hpp"
#include "strata/app/run_outputs.hpp"
#include "strata/app/vtk_series.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/core/sim/simulation.hpp"
#include "strata/core/sim/stable_time_step.hpp"
#include "strata/core/sim/steppers/time_stepper.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/meshing/implicit_shape.hpp"
#include "strata/meshing/level_set_obstacle.hpp"
#include "strata/meshing/surface_binding.hpp"
#include "strata/meshing/surface_io.hpp"

namespace strata::app {
namespace {

using Clock = std::chrono::steady_clock;

bool is_explicit(const SolverSettings& settings) {
  return find_stepper(settings).is_explicit;
}

}  // namespace

namespace detail {

std::vector<Obstacle> build_obstacles(const Scene& scene, double mean_edge) {
  std::vector<Obstacle> obstacles;
  if (scene.ground) {
    obstacles.push_back(plane_obstacle("ground", scene.ground->point, scene.ground->normal));
    obstacles.back().friction = scene.ground->friction;
  }
  for (const ObstacleSpec& spec : scene.obstacles) {
    Obstacle obstacle;
    LevelSetOptions options;
    options.voxel_size = spec.voxel_size > 0.0 ? spec.voxel_size : 0.5 * mean_edge;
    // Contact samples the tricubic interpolant, whose stencil reaches 2√3 voxels from a point:
    // a band of 4 voxels keeps it on the voxel values within half a voxel of the surface.
    options.half_width = 4.0;
    if (spec.plane_point) {
      obstacle = plane_obstacle(spec.name, *spec.plane_point, *spec.plane_normal);
    } else if (spec.implicit) {
      obstacle = level_set_obstacle(
          spec.name, std::make_shared<LevelSet>(implicit_shape_level_set(*spec.implicit, options)));
    } else if (spec.level_set) {
      obstacle = level_set_obstacle(
          spec.name, std::make_shared<LevelSet>(LevelSet::read_vdb(*spec.level_set, spec.grid)));
    } else {
      SurfaceLevelSet converted = surface_to_level_set(read_surface(*spec.surface), options);
      obstacle =
          level_set_obstacle(spec.name, std::make_shared<LevelSet>(std::move(converted.level_set)));
    }
    obstacle.friction = spec.friction;
    obstacle.velocity = spec.velocity;
    obstacles.push_back(std::move(obstacle));
  }
  return obstacles;
}

}  // namespace detail

namespace {

std::vector<Obstacle> build_obstacles(const Scene& scene, const TetMesh& mesh) {
  // With a hierarchy the finest level's vertices touch the obstacles: its edges, halved per
  // level, set the default voxel.
  const int levels = scene.hierarchy ? scene.hierarchy->levels : 0;
  return detail::build_obstacles(scene,
                                 std::ldexp(mean_edge_length(mesh.vertices, mesh.tets), -levels));
}

/// The scene's run (SimulationRun): a plain Simulation on the mesh, or (scene key "hierarchy") an
/// AdaptiveSimulation on an active cut of the refinement tree over it. Stepping, the current
/// mesh's state and the counters go through the interface; `adaptive()` gives the hierarchy's own
/// outputs (probes through the tree, per-cell levels, the stats block).
class SceneSimulation {
 public:
  /// Core InputErrors get the scene file as prefix.
  /// `binding`: the fine surface bound to `mesh` (it collides with the obstacles); may be null.
  /// `surface_rest`: its rest vertices (with `binding`).
  SceneSimulation(const Scene& scene, const TetMesh& mesh, const SurfaceBinding* binding,
                  const MatrixX3d* surface_rest) {
    try {
      if (scene.hierarchy && scene.hierarchy->mode != HierarchyMode::adaptive) {
        // Full and uniform cuts hold every tet of their level.
        const HierarchySettings& h = *scene.hierarchy;
        const int level = h.mode == HierarchyMode::full ? h.levels : h.level;
        check_fits_in_memory(
            std::ldexp(static_cast<double>(mesh.tets.rows()), 3 * level),
            h.mode == HierarchyMode::full ? "hierarchy.levels" : "hierarchy.level");
      }
      std::vector<Obstacle> obstacles = build_obstacles(scene, mesh);
      const bool has_obstacles = !obstacles.empty();
      ProblemSpec problem{.material = scene.material,
                          .dirichlet = scene.dirichlet_groups(),
                          .loads = scene.forces,
                          .gravity = scene.gravity,
                          .obstacles = std::move(obstacles)};
      if (scene.hierarchy) {
        // The fine surface's vertices as material points of the tree (bound to the coarse mesh,
        // the tree's roots): each cut embeds them in its active tets.
        std::vector<RootPoint> contact_surface;
        if (has_obstacles && binding != nullptr)
          for (Index i = 0; i < binding->tets.size(); ++i)
            contact_surface.push_back({binding->tets[i], surface_rest->row(i).transpose()});
        auto adaptive = std::make_unique<AdaptiveSimulation>(
            mesh, *scene.hierarchy, std::move(problem), scene.solver, std::move(contact_surface));
        m_adaptive = adaptive.get();
        m_run = std::move(adaptive);
      } else {
        SimulationOptions options;
        options.surface_springs = scene.surface_springs;
        if (has_obstacles && binding != nullptr) {
          // The fine surface collides too: its vertices are contact points through their binding.
          for (Index i = 0; i < binding->corners.rows(); ++i)
            options.contact_points.push_back(
                {{binding->corners(i, 0), binding->corners(i, 1), binding->corners(i, 2),
                  binding->corners(i, 3)},
                 {binding->barycentric(i, 0), binding->barycentric(i, 1),
                  binding->barycentric(i, 2), binding->barycentric(i, 3)}});
        }
        const bool box = !scene.mesh.file && !scene.mesh.surface && !scene.mesh.level_set &&
                         !scene.mesh.implicit;
        if (box && is_explicit(scene.solver)) {
          // The stable-step bound over each cell's six tets (stable_time_step.hpp): the cells of
          // a box are congruent (mirror images), and box_tet_mesh writes a cell's tets in a row.
          const MatrixX4i cell = mesh.tets.topRows(6);
          options.max_angular_frequency = max_angular_frequency_bound(
              mesh.vertices, cell, scene.material, std::vector<int>(6, 0));
        }
        m_run = std::make_unique<Simulation>(mesh, std::move(problem), scene.solver,
                                             std::move(options));
      }
    } catch (const InputError& error) {
      throw InputError(scene.file.string() + ": " + error.what());
    }
  }
  void advance() { m_run->advance(); }
  bool finished() const { return m_run->finished(); }
  /// The Simulation of the current mesh (the active cut's, for a hierarchy).
  const Simulation& current() const { return m_run->current(); }
  const AdaptiveSimulation* adaptive() const { return m_adaptive; }
  SimulationCounters counters() const { return m_run->counters(); }

 private:
  std::unique_ptr<SimulationRun> m_run;
  const AdaptiveSimulation* m_adaptive = nullptr;
};

/// stats.json's "hierarchy" block: settings, the active-cut history and every cut change.
nlohmann::json hierarchy_json(const AdaptiveSimulation& adaptive, bool finished) {
  const HierarchySettings& settings = adaptive.settings();
  nlohmann::json block;
  block["mode"] = to_string(settings.mode);
  block["levels"] = settings.levels;
  block["level"] = settings.level;
  block["indicator"] = settings.indicator;
  block["refine_threshold"] = settings.criteria.refine_threshold;
  block["coarsen_tolerance"] = settings.criteria.coarsen_tolerance;
  block["root_tets"] = adaptive.tree().num_roots();
  block["finest_level_tets"] =
      static_cast<double>(adaptive.tree().num_roots()) * std::pow(8.0, settings.levels);
  block["tree_nodes"] = adaptive.tree().num_nodes();
  block["tree_memory_bytes"] = adaptive.tree().memory_bytes();
  block["active_level_counts"] = adaptive.cut().level_counts();
  block["bookkeeping_seconds"] = adaptive.bookkeeping_seconds();
  block["stepping_seconds"] = adaptive.stepping_seconds();
  nlohmann::json history = {{"step", nlohmann::json::array()},
                            {"time", nlohmann::json::array()},
                            {"tets", nlohmann::json::array()},
                            {"dofs", nlohmann::json::array()},
                            {"hanging_vertices", nlohmann::json::array()},
                            {"estimated_error", nlohmann::json::array()},
                            {"estimated_energy_error", nlohmann::json::array()},
                            {"estimated_upper_error", nlohmann::json::array()},
                            {"estimated_load_work_error", nlohmann::json::array()},
                            {"estimated_local_error", nlohmann::json::array()}};
  for (const CutSample& sample : adaptive.history()) {
    history["step"].push_back(sample.step);
    history["time"].push_back(sample.time);
    history["tets"].push_back(sample.tets);
    history["dofs"].push_back(sample.dofs);
    history["hanging_vertices"].push_back(sample.hanging);
    history["estimated_error"].push_back(sample.estimated_error);
    history["estimated_energy_error"].push_back(sample.estimated_energy_error);
    history["estimated_upper_error"].push_back(sample.estimated_upper_error);
    history["estimated_load_work_error"].push_back(sample.estimated_load_work_error);
    history["estimated_local_error"].push_back(sample.estimated_local_error);
  }
  block["history"] = history;
  Index refinements = 0, coarsenings = 0;
  nlohmann::json changes = nlohmann::json::array();
  for (const CutChangeRecord& change : adaptive.changes()) {
    refinements += change.refined;
    coarsenings += change.coarsened;
    changes.push_back({{"step", change.step},
                       {"pass", change.pass},
                       {"time", change.time},
                       {"refined", change.refined},
                       {"coarsened", change.coarsened},
                       {"tets_before", change.tets_before},
                       {"tets_after", change.tets_after},
                       {"dofs_after", change.dofs_after},
                       {"energy_before", change.energy_before},
                       {"energy_after", change.energy_after},
                       {"seconds", change.seconds},
                       {"phase_seconds",
                        {{"edit", change.phases.edit},
                         {"flatten", change.phases.flatten},
                         {"elastic_model", change.phases.elastic_model},
                         {"reduced_model", change.phases.reduced_model},
                         {"problem", change.phases.problem},
                         {"stepper", change.phases.stepper},
                         {"transfer", change.phases.transfer},
                         {"records", change.phases.records}}},
                       {"multigrid_setups", change.multigrid_setups},
                       {"multigrid_carried_setups", change.multigrid_carried_setups},
                       {"multigrid_setup_seconds", change.multigrid_setup_seconds},
                       {"plastic_merge_change", change.plastic_merge_change},
                       {"contact_correction", change.contact_correction}});
  }
  block["refinements"] = refinements;
  block["coarsenings"] = coarsenings;
  block["changes"] = changes;
  const ToleranceReport& report = adaptive.tolerance_report();
  block["tolerance"] = report.tolerance;
  block["estimated_error"] = report.max_estimated_error;
  // A run that stopped early met nothing to its end.
  block["tolerance_met"] = finished && report.steps_over_tolerance == 0;
  block["steps_over_tolerance"] = report.steps_over_tolerance;
  block["steps_out_of_passes"] = report.steps_out_of_passes;
  block["steps_unrefinable"] = report.steps_unrefinable;
  block["estimate_scale"] = report.estimate_scale;
  block["refused_refinements"] = report.refused_refinements;
  block["redone_steps"] = report.redone_steps;
  block["calibration_passes"] = report.calibration_passes;
  block["redo_seconds"] = report.redo_seconds;
  block["initial_refinements"] = report.initial_refinements;
  block["initial_passes"] = report.initial_passes;
  block["initial_newton_iterations"] = report.initial_newton_iterations;
  block["initial_adaptation_seconds"] = report.initial_adaptation_seconds;
  block["full_resolution_fraction"] = settings.full_resolution_fraction;
  block["full_resolution_fraction_in_use"] = adaptive.full_resolution_fraction();
  block["coarsen_budget"] = settings.coarsen_budget;
  if (report.full_resolution_step >= 0) {
    block["full_resolution_step"] = report.full_resolution_step;
  } else {
    block["full_resolution_step"] = nullptr;
  }
  if (settings.mode == HierarchyMode::precomputed) {
    const PrecomputedCut& cut = *settings.precomputed;
    nlohmann::json starts = nlohmann::json::array();
    for (const CutWindow& window : cut.windows)
      starts.push_back(window.start);
    block["precomputed"] = {{"cut", cut.name},
                            {"windows", cut.windows.size()},
                            {"window_starts", starts},
                            {"sources", cut.sources},
                            {"recorded_tolerance", cut.tolerance}};
  }
  return block;
}

nlohmann::json stats_json(const Scene& scene, const PreparedMesh& prepared,
                          const SceneSimulation& scene_simulation, const RunSummary& summary) {
  const Simulation& simulation = scene_simulation.current();
  const SimulationCounters counters = scene_simulation.counters();
  nlohmann::json stats;
  stats["status"] = summary.status;
  if (!summary.message.empty()) stats["message"] = summary.message;
  stats["scene"] = scene.file.string();
  stats["wall_seconds"] = summary.wall_seconds;
  stats["steps"] = counters.steps;
  stats["newton_iterations"] = counters.newton_iterations;
  stats["element_evaluations"] = counters.element_evaluations;
  stats["factorizations"] = counters.factorizations;
  stats["newton"] = {{"exact_hessian_iterations", counters.exact_hessian_iterations},
                     {"shifted_hessian_iterations", counters.shifted_hessian_iterations},
                     {"projected_hessian_iterations", counters.projected_hessian_iterations},
                     {"increment_converged_steps", counters.increment_converged_steps},
                     {"stalled_steps", counters.stalled_steps},
                     {"linear_iterations", counters.linear_iterations},
                     {"reused_factor_solves", counters.reused_factor_solves},
                     {"max_residual_ratio", counters.max_residual_ratio},
                     {"linear_solver", to_string(counters.linear_solver)},
                     {"multigrid_setups", counters.multigrid_setups},
                     {"multigrid_carried_setups", counters.multigrid_carried_setups},
                     {"multigrid_setup_seconds", counters.multigrid_setup_seconds},
                     {"multigrid_direct_fallbacks", counters.multigrid_direct_fallbacks}};
  if (counters.stalled_steps > 0)
    stats["newton"]["note"] = std::to_string(counters.stalled_steps) +
                              " Newton solve(s) stopped with the residual stalled (at round-off, "
                              "or below 1e-5 of the load scale) (up to " +
                              std::to_string(counters.max_residual_ratio) +
                              " x the residual target) and were accepted as converged";
  stats["threads"] = max_threads();
  stats["huge_pages"] = huge_page_heap_state();
  stats["vertices"] = simulation.mesh().vertices.rows();
  stats["tets"] = simulation.mesh().tets.rows();
  stats["dofs"] = simulation.embedded_model().num_dofs();
  Index constrained = 0;
  std::vector<std::string> groups;
  for (const DirichletGroup& group : simulation.dirichlet_groups()) {
    const Index components =
        group.spec.components[0] + group.spec.components[1] + group.spec.components[2];
    constrained += components * static_cast<Index>(group.vertices.size());
    groups.push_back(group.spec.name);
  }
  stats["free_dofs"] = simulation.embedded_model().num_dofs() - constrained;
  stats["groups"] = groups;
  stats["mesh_source"] = prepared.source;
  stats["reoriented_tets"] = prepared.reoriented_tets;
  stats["removed_vertices"] = prepared.removed_vertices;
  if (prepared.meshing) stats["meshing"] = meshing_stats_json(*prepared.meshing);
  stats["material"] = {{"model", to_string(scene.material.model)},
                       {"youngs_modulus", scene.material.youngs_modulus},
                       {"poisson_ratio", scene.material.poisson_ratio},
                       {"density", scene.material.density},
                       {"mass_damping", scene.material.mass_damping},
                       {"stiffness_damping", scene.material.stiffness_damping}};
  if (const SurfaceSprings* springs = simulation.surface_springs()) {
    stats["surface_springs"] = {{"springs", springs->size()},
                                {"youngs_modulus", scene.surface_springs->youngs_modulus},
                                {"fraction", scene.surface_springs->fraction},
                                {"yield_events", springs->yield_events()},
                                {"largest_plastic_strain", springs->largest_plastic_strain()}};
    if (std::isfinite(scene.surface_springs->yield_strain))
      stats["surface_springs"]["yield_strain"] = scene.surface_springs->yield_strain;
  }
  if (simulation.has_obstacles()) {
    const ContactSettings& contact = simulation.contact_settings();
    const AdaptiveSimulation* adaptive = scene_simulation.adaptive();
    stats["contact"] = {
        {"max_penetration", adaptive ? adaptive->max_penetration() : simulation.max_penetration()},
        {"tolerance", contact.distance},
        {"barrier_stiffness", contact.stiffness},
        {"friction_slip", contact.friction_slip},
        {"points", simulation.contact_points()},
        {"surface_points", simulation.extra_contact_points()},
        {"finest_boundary_points", adaptive != nullptr && adaptive->finest_contact_points()},
        {"active_contacts", adaptive ? adaptive->contact_counts() : simulation.contact_counts()}};
  }
  if (scene.material.plasticity) {
    const Plasticity& plasticity = *scene.material.plasticity;
    nlohmann::json block = {{"yield_stress", plasticity.yield_stress},
                            {"hardening", plasticity.hardening},
                            {"passes", counters.plastic_passes},
                            {"unconverged_steps", counters.plastic_unconverged_steps},
                            {"yielded_tets", counters.yielded_tets}};
    if (std::isfinite(plasticity.max_plastic_strain))
      block["max_plastic_strain"] = plasticity.max_plastic_strain;
    const VectorXd& strain = simulation.plastic_state().equivalent_strain;
    block["largest_plastic_strain"] = strain.size() > 0 ? strain.maxCoeff() : 0.0;
    Index plastic_tets = 0;
    for (Index t = 0; t < strain.size(); ++t)
      plastic_tets += strain[t] > 0.0;
    block["plastic_tets"] = plastic_tets;
    stats["plasticity"] = block;
  }
  stats["mode"] = to_string(scene.solver.mode);
  if (scene.solver.mode == SimulationMode::dynamic) {
    stats["integrator"] = to_string(scene.solver.integrator);
    stats["dt"] = scene.solver.dt;
    stats["duration"] = scene.solver.duration;
    stats["final_time"] = simulation.time();
  } else {
    stats["load_steps"] = scene.solver.load_steps;
    stats["final_load_factor"] = simulation.time();
  }
  stats["stable_dt_estimate"] = simulation.stable_dt_estimate();
  const bool finite = simulation.positions().allFinite() && simulation.velocities().allFinite();
  if (finite) {
    stats["energies"] = {{"kinetic", simulation.kinetic_energy()},
                         {"elastic", simulation.elastic_energy()},
                         {"external_potential", simulation.external_potential_energy()}};
    const VectorXd u = simulation.positions() - simulation.model().rest_positions();
    double max_displacement = 0.0;
    for (Index v = 0; v < u.size() / 3; ++v) {
      max_displacement = std::max(max_displacement, u.segment<3>(3 * v).norm());
    }
    stats["max_displacement"] = max_displacement;
  }
  stats["frames"] = summary.frames;
  stats["probes"] = scene.output.probes.size();
  if (scene_simulation.adaptive())
    stats["hierarchy"] = hierarchy_json(*scene_simulation.adaptive(), summary.status == "ok");
  return stats;
}

void write_json(const std::filesystem::path& path, const nlohmann::json& value) {
  write_file_atomically(path, [&value](std::ostream& out) { out << value.dump(2) << '\n'; });
}

}  // namespace

RunSummary run_scene(const Scene& scene, const RunOptions& options) {
  if (scene.body.skeleton_springs) return detail::run_spring_body_scene(scene, options);
  const Clock::time_point start = Clock::now();
  std::ostream& log = options.log ? *options.log : std::cout;
  RunSummary summary;
  summary.output_dir = options.output_dir.empty() ? default_output_dir(scene) : options.output_dir;
  check_output_folder(summary.output_dir);
  for (const std::string& ignored : scene.ignored_keys)
    std::cerr << "strata: warning: " << scene.file.string() << ": " << ignored << "\n";

  PreparedMesh prepared = prepare_scene_mesh(scene);
  const auto [lo, hi] = bounding_box(prepared.mesh.vertices);
  const double diagonal = (hi - lo).norm();
  const TetLocator locator(prepared.mesh.vertices, prepared.mesh.tets);
  MatrixX3d probe_points(scene.output.probes.size(), 3);
  for (std::size_t i = 0; i < scene.output.probes.size(); ++i) {
    probe_points.row(i) = scene.output.probes[i].transpose();
  }
  std::vector<TetLocation> probe_locations;
  try {
    probe_locations =
        locate_points(locator, probe_points, kProbeToleranceFactor * diagonal, "output.probes");
  } catch (const InputError& error) {
    throw InputError(scene.file.string() + ": " + error.what());
  }
  // The fine surface, bound once to the simulation mesh: rendered with the frames and, with
  // obstacles, tested for contact.
  std::optional<FineSurface> surface;
  const bool has_contact = scene.ground || !scene.obstacles.empty();
  if (scene.mesh.surface && (scene.output.vtk || has_contact))
    surface.emplace(read_surface(*scene.mesh.surface), prepared.mesh);
  SceneSimulation scene_simulation(scene, prepared.mesh, surface ? &surface->binding() : nullptr,
                                   surface ? &surface->rest().vertices : nullptr);
  const Simulation* simulation = &scene_simulation.current();
  summary.stable_dt_estimate = simulation->stable_dt_estimate();
  std::vector<RootPoint> probe_roots;
  if (const AdaptiveSimulation* adaptive = scene_simulation.adaptive()) {
    const Index budget = adaptive->settings().criteria.max_active_elements;
    if (adaptive->settings().mode == HierarchyMode::adaptive && budget > 0 &&
        budget < adaptive->tree().num_roots()) {
      log.flush();
      std::cerr << "strata: warning: " << scene.file.string()
                << ": hierarchy.max_active_elements: " << budget << " is below the "
                << adaptive->tree().num_roots() << " roots (the cut cannot refine)\n";
    }
    try {
      probe_roots =
          adaptive->locate(probe_points, "output.probes", kProbeToleranceFactor * diagonal);
    } catch (const InputError& error) {
      throw InputError(scene.file.string() + ": " + error.what());
    }
  }

  if (!options.quiet) {
    log << "strata: " << scene.file.string() << ": " << prepared.mesh.vertices.rows()
        << " vertices, " << prepared.mesh.tets.rows() << " tets";
    if (prepared.reoriented_tets > 0) log << " (" << prepared.reoriented_tets << " reoriented)";
    if (prepared.removed_vertices > 0) {
      log << " (" << prepared.removed_vertices << " unreferenced vertices removed)";
    }
    if (const AdaptiveSimulation* adaptive = scene_simulation.adaptive()) {
      log << "; hierarchy " << to_string(adaptive->settings().mode) << ", "
          << adaptive->settings().levels << " levels, " << adaptive->cut().size() << " active tets";
    }
    log << ", " << to_string(scene.material.model) << ", " << to_string(scene.solver.mode);
    if (scene.solver.mode == SimulationMode::dynamic) {
      log << " " << to_string(scene.solver.integrator) << ", dt " << scene.solver.dt << " s, "
          << planned_steps(scene.solver) << " steps\n";
    } else {
      log << ", " << scene.solver.load_steps << " load steps\n";
    }
  }
  if (is_explicit(scene.solver)) {
    if (!options.quiet) {
      log << "strata: stable dt estimate " << summary.stable_dt_estimate << " s\n";
    }
    if (scene.solver.dt > summary.stable_dt_estimate) {
      log.flush();
      std::cerr << "strata: warning: dt = " << scene.solver.dt << " s exceeds the stable estimate "
                << summary.stable_dt_estimate << " s of " << to_string(scene.solver.integrator)
                << "; the run will likely diverge\n";
    }
  }
  log.flush();

  const OutputFolder output_folder(summary.output_dir);
  ProgressBar progress(options.progress, options.progress_file);
  // A previous run's stats.json would describe this run's outputs if it stopped before writing
  // its own (interrupted): stats.json exists only for a run that ended, and is this run's.
  std::filesystem::remove(summary.output_dir / "stats.json");
  ProbeRecorder probes(summary.output_dir / "probes.csv", prepared.mesh, scene.output.probes,
                       std::move(probe_locations));
  ReactionRecorder reactions(summary.output_dir / "reactions.csv");
  std::optional<VtkSeries> vtk;
  if (scene.output.vtk)
    vtk.emplace(summary.output_dir, scene.name, scene.output.vtk_mesh, scene.output.vtk_encoding);
  if (surface) {
    if (!options.quiet) {
      log << "strata: surface " << scene.mesh.surface->string() << ": "
          << surface->rest().vertices.rows() << " vertices bound in "
          << format_duration(surface->bind_seconds()) << " (" << surface->binding().num_outside
          << " outside the mesh, at most " << surface->max_outside_distance() << " m)\n";
    }
  }
  std::vector<RootPoint> surface_roots;  // the surface's vertices as material points of the tree
  if (surface && scene_simulation.adaptive()) {
    const SurfaceBinding& binding = surface->binding();
    for (Index i = 0; i < binding.tets.size(); ++i)
      surface_roots.push_back({binding.tets[i], surface->rest().vertices.row(i).transpose()});
  }

  const auto write_frame = [&]() {
    simulation = &scene_simulation.current();  // a hierarchy rebuilds it when the cut changes
    const double time = simulation->time();
    const AdaptiveSimulation* adaptive = scene_simulation.adaptive();
    if (adaptive) {
      probes.record_displacements(time, adaptive->displacements(probe_roots));
    } else {
      probes.record(time, simulation->positions() - simulation->model().rest_positions());
    }
    reactions.record(time, simulation->reactions());
    if (vtk) {
      const VectorXi levels = adaptive ? adaptive->cell_levels() : VectorXi();
      vtk->write_frame(time, *simulation, adaptive ? &levels : nullptr);
    }
    if (vtk && surface && (adaptive || surface->matches(simulation->mesh()))) {
      // On a hierarchy the surface follows the active cut: each vertex is interpolated in the
      // active ancestor of the leaf holding it (bound once to the coarse mesh = the tree's roots).
      const MatrixX3d surface_positions =
          adaptive ? MatrixX3d(surface->rest().vertices + adaptive->displacements(surface_roots))
                   : surface->positions(simulation->positions());
      VtuFields fields = surface->fields(surface_positions);
      const std::vector<Vector3d> contact = simulation->surface_contact_forces();
      if (static_cast<Index>(contact.size()) == surface_positions.rows()) {
        Eigen::MatrixXd forces(surface_positions.rows(), 3);
        for (Index i = 0; i < forces.rows(); ++i)
          forces.row(i) = contact[i].transpose();
        fields.add_point_data("contact_force", std::move(forces));
      }
      vtk->write_surface_frame(time, surface_positions, surface->rest().triangles, fields);
    }
    ++summary.frames;
  };
  const auto save_tables = [&]() {
    probes.csv().save();
    reactions.csv().save();
  };
  const auto finish = [&]() {
    summary.steps = scene_simulation.current().step_count();
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    write_json(summary.output_dir / "stats.json",
               stats_json(scene, prepared, scene_simulation, summary));
  };

  write_frame();
  save_tables();
  if (options.on_step && scene_simulation.adaptive()) options.on_step(*scene_simulation.adaptive());
  const long total_steps = planned_steps(scene.solver);
  try {
    while (!scene_simulation.finished()) {
      scene_simulation.advance();
      simulation = &scene_simulation.current();
      if (options.on_step && scene_simulation.adaptive())
        options.on_step(*scene_simulation.adaptive());
      const long step = simulation->step_count();
      if (step % scene.output.every == 0 || simulation->finished()) {
        write_frame();
        probes.csv().save_if_due();
        reactions.csv().save_if_due();
      }
      const bool dynamic = scene.solver.mode == SimulationMode::dynamic;
      char label[64];
      std::snprintf(label, sizeof label, dynamic ? "t = %.4g s" : "load factor %.4g",
                    simulation->time());
      progress.update(static_cast<double>(step) / total_steps, label);
    }
  } catch (const DivergenceError& error) {
    progress.clear();
    summary.status = "diverged";
    summary.message = error.what();
    // A static body that its constraints do not hold has no unique equilibrium: say so.
    int free_motions = 0;
    if (scene.solver.mode == SimulationMode::static_equilibrium && !has_contact) {
      try {
        const Simulation& last = scene_simulation.current();
        free_motions = free_rigid_motions(last.dirichlet_groups(), last.model().rest_positions());
      } catch (const std::logic_error&) {
        // a failed cut change left no Simulation to ask
      }
    }
    if (free_motions > 0) {
      summary.message += "; the fixed and prescribed groups leave " + std::to_string(free_motions) +
                         " rigid motion" + (free_motions > 1 ? "s" : "") +
                         " of the body free, so a static equilibrium is not unique: hold at "
                         "least three vertices not on one line (or run it dynamic)";
    }
    save_tables();
    finish();
    if (free_motions > 0) throw DivergenceError(summary.message, error.step(), error.time());
    throw;
  }
  progress.clear();
  save_tables();
  finish();
  if (const SimulationCounters counters = scene_simulation.counters();
      counters.plastic_unconverged_steps > 0) {
    log.flush();
    std::cerr << "strata: warning: " << scene.file.string()
              << ": the plastic state had not settled "
              << "within solver.max_plastic_passes = " << scene.solver.plasticity.max_passes
              << " at " << counters.plastic_unconverged_steps << " of " << summary.steps
              << " steps (solver.plastic_tolerance " << scene.solver.plasticity.tolerance << ")\n";
  }
  if (const AdaptiveSimulation* adaptive = scene_simulation.adaptive();
      adaptive && (adaptive->settings().mode == HierarchyMode::adaptive ||
                   adaptive->settings().mode == HierarchyMode::precomputed)) {
    const ToleranceReport& report = adaptive->tolerance_report();
    if (report.steps_over_tolerance > 0) {
      log.flush();
      std::cerr << "strata: warning: " << scene.file.string() << ": the estimated error exceeded "
                << "hierarchy.tolerance " << report.tolerance << " at "
                << report.steps_over_tolerance << " of " << summary.steps << " steps (largest "
                << report.max_estimated_error;
      if (adaptive->settings().mode == HierarchyMode::precomputed) {
        std::cerr << ") on the precomputed cut " << adaptive->settings().precomputed->name
                  << ": it does not capture this scene (precompute it with these loads, or at a "
                     "tighter --tolerance)\n";
      } else {
        // Only the limits this run has can have refused a refinement: the deepest level allowed
        // and the explicit step limit keep tets from refining at all, the element budget and
        // hysteresis for a while.
        const HierarchySettings& h = adaptive->settings();
        std::vector<std::string> hard;
        if (h.criteria.max_level >= 0 && h.criteria.max_level < h.levels)
          hard.push_back("hierarchy.max_level");
        else
          hard.push_back("the finest level (hierarchy.levels)");
        if (is_explicit(scene.solver)) hard.push_back("the explicit step limit");
        std::vector<std::string> limits = hard;
        if (h.criteria.max_active_elements > 0) limits.push_back("hierarchy.max_active_elements");
        if (h.criteria.min_steps_between_changes > 0)
          limits.push_back("hysteresis (hierarchy.min_steps_between_changes)");
        const auto either = [&](const std::vector<std::string>& names) {
          std::string text;
          for (std::size_t k = 0; k < names.size(); ++k)
            text += (k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + names[k];
          return text;
        };
        const auto count = [](long n, const char* one, const char* many) {
          return std::to_string(n) + " " + (n == 1 ? one : many);
        };
        if (report.refused_refinements > 0)
          std::cerr << "; " << count(report.refused_refinements, "refusal", "refusals")
                    << " to refine (a tet refused at several passes counts at each) by "
                    << either(limits);
        if (report.steps_unrefinable > 0)
          std::cerr << "; " << count(report.steps_unrefinable, "decision", "decisions")
                    << " on a cut no tet of which may refine (" << either(hard) << ")";
        if (report.steps_out_of_passes > 0)
          std::cerr << "; " << count(report.steps_out_of_passes, "step", "steps")
                    << " still refining after all " << h.max_passes << " hierarchy.max_passes";
        std::cerr << ")\n";
      }
    }
  }
  if (const AdaptiveSimulation* adaptive = scene_simulation.adaptive();
      adaptive && !options.quiet && adaptive->tolerance_report().full_resolution_step >= 0) {
    const long step = adaptive->tolerance_report().full_resolution_step;
    const bool explicit_limit =
        adaptive->full_resolution_fraction() < adaptive->settings().full_resolution_fraction;
    log << "strata: the cut would have held more than "
        << 100.0 * adaptive->full_resolution_fraction() << " % of the finest level's tets "
        << (step == 0 ? std::string("before the first step") : "after step " + std::to_string(step))
        << ": the run went on at full resolution ("
        << (explicit_limit
                ? std::string("beyond this share an adaptive step of ") +
                      to_string(scene.solver.integrator) + " costs more than a full-resolution one"
                : std::string("hierarchy.full_resolution_fraction"))
        << ")\n";
  }
  if (!options.quiet) {
    log << "strata: done: " << summary.steps << " steps, " << summary.frames << " frames in "
        << format_duration(summary.wall_seconds) << "; output in " << summary.output_dir.string()
        << "\n";
  }
  return summary;
}

}  // namespace strata::app
