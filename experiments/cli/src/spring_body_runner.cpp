#include "spring_body_runner.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "strata/app/huge_pages.hpp"
#include "strata/app/progress_bar.hpp"
#include "strata/app/run_outputs.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/pvd.hpp"
#include "strata/core/io/vtp.hpp"
#include "strata/core/sim/stable_time_step.hpp"
#include "strata/meshing/curve_skeleton.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/surface_simplification.hpp"
#include "strata/meshing/triangle_frame_binding.hpp"

namespace strata::app::detail {
namespace {

using Clock = std::chrono::steady_clock;

/// Each probe's nearest point at rest among `points` (the shown surface's vertices, then the
/// skeleton's); a probe farther than 5 % of the body's bounding-box diagonal from every point is
/// an error naming it.
std::vector<Index> locate_probes(const Scene& scene, ConstRef<MatrixX3d> points) {
  const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  std::vector<Index> nearest;
  for (std::size_t p = 0; p < scene.output.probes.size(); ++p) {
    Index best = 0;
    (points.rowwise() - scene.output.probes[p].transpose()).rowwise().squaredNorm().minCoeff(&best);
    const double distance = (points.row(best).transpose() - scene.output.probes[p]).norm();
    if (distance > 0.05 * diagonal) {
      char text[200];
      std::snprintf(text, sizeof text,
                    ": output.probes.%zu: (%g, %g, %g) is %g m from the body's nearest vertex "
                    "(at most 5 %% of its size, %g m)",
                    p, scene.output.probes[p].x(), scene.output.probes[p].y(),
                    scene.output.probes[p].z(), distance, 0.05 * diagonal);
      throw InputError(scene.file.string() + text);
    }
    nearest.push_back(best);
  }
  return nearest;
}

}  // namespace

RunSummary run_spring_body_scene(const Scene& scene, const RunOptions& options) {
  const Clock::time_point start = Clock::now();
  std::ostream& log = options.log ? *options.log : std::cout;
  RunSummary summary;
  summary.output_dir = options.output_dir.empty() ? default_output_dir(scene) : options.output_dir;
  check_output_folder(summary.output_dir);
  for (const std::string& ignored : scene.ignored_keys)
    std::cerr << "strata: warning: " << scene.file.string() << ": " << ignored << "\n";
  const std::string where = scene.file.string() + ": mesh.surface";
  SurfaceMesh shown;  // the surface as given, drawn and probed
  try {
    shown = read_surface(*scene.mesh.surface);
  } catch (const InputError& error) {
    throw InputError(where + ": " + error.what());
  }
  // The springs' surface: `shown` simplified (then carrying `shown` in its triangles' frames), or
  // `shown` itself.
  const bool simplified =
      scene.body.surface_vertices > 0 && shown.vertices.rows() > scene.body.surface_vertices;
  const Clock::time_point simplify_start = Clock::now();
  const SurfaceMesh surface =
      simplified ? simplify_surface(shown, scene.body.surface_vertices, where) : shown;
  std::optional<TriangleFrameBinding> binding;
  if (simplified) {
    try {
      binding = bind_to_triangles(surface.vertices, surface.triangles, shown.vertices);
    } catch (const InputError& error) {
      throw InputError(where + ": binding to the simplified surface: " + error.what());
    }
  }
  const double simplify_seconds =
      std::chrono::duration<double>(Clock::now() - simplify_start).count();
  const CurveSkeleton skeleton = curve_skeleton(surface, where);
  std::vector<std::array<int, 2>> segments;
  for (Index e = 0; e < skeleton.edges.rows(); ++e)
    segments.push_back({skeleton.edges(e, 0), skeleton.edges(e, 1)});
  std::unique_ptr<SpringBodySimulation> run;
  try {
    SpringBody body =
        skeleton_spring_body(surface.vertices, surface.triangles, skeleton.points, segments,
                             skeleton.owner, scene.material, scene.body.rule, "body");
    std::vector<Obstacle> obstacles =
        build_obstacles(scene, mean_triangle_edge_length(shown.vertices, shown.triangles));
    run = std::make_unique<SpringBodySimulation>(std::move(body),
                                                 ProblemSpec{.material = scene.material,
                                                             .dirichlet = scene.dirichlet_groups(),
                                                             .loads = scene.forces,
                                                             .gravity = scene.gravity,
                                                             .obstacles = std::move(obstacles)},
                                                 scene.solver);
  } catch (const InputError& error) {
    throw InputError(scene.file.string() + ": " + error.what());
  }
  const SpringBody& body = run->body();
  const Index S = body.num_surface;
  const Index V = body.rest.rows();
  const Index shown_count = shown.vertices.rows();
  // The shown surface's vertices, then the skeleton's, at positions x (3·#V).
  const auto shown_points = [&](const VectorXd& x) {
    MatrixX3d points(shown_count + V - S, 3);
    if (binding) {
      points.topRows(shown_count) = deformed_points(*binding, body.triangles, x);
    } else {
      for (Index i = 0; i < S; ++i)
        points.row(i) = x.segment<3>(3 * i).transpose();
    }
    for (Index k = S; k < V; ++k)
      points.row(shown_count + k - S) = x.segment<3>(3 * k).transpose();
    return points;
  };
  VectorXd rest_positions(3 * V);
  for (Index i = 0; i < V; ++i)
    rest_positions.segment<3>(3 * i) = body.rest.row(i).transpose();
  const MatrixX3d shown_rest = shown_points(rest_positions);
  const std::vector<Index> probe_points = locate_probes(scene, shown_rest);
  const long total_steps = planned_steps(scene.solver);
  if (!options.quiet) {
    log << "strata: " << scene.file.string() << ": skeleton springs on "
        << scene.mesh.surface->string() << ": " << body.num_surface << " surface vertices"
        << (simplified ? " (simplified from " + std::to_string(shown_count) + " in " +
                             format_duration(simplify_seconds) + ")"
                       : std::string())
        << ", " << body.rest.rows() - body.num_surface << " skeleton points (skeletonized in "
        << format_duration(skeleton.seconds) << "), " << body.springs.size() << " springs ("
        << body.count(SpringKind::surface) << " surface, " << body.count(SpringKind::tie)
        << " ties, " << body.count(SpringKind::skeleton) << " skeleton), mass "
        << body.vertex_mass.sum() << " kg, " << to_string(scene.solver.integrator) << ", dt "
        << scene.solver.dt << " s, " << total_steps << " steps\n";
    if (scene.solver.integrator != Integrator::implicit_euler)
      log << "strata: stable dt estimate " << run->stable_dt_estimate() << " s\n";
  }
  if (scene.solver.integrator != Integrator::implicit_euler &&
      scene.solver.dt > run->stable_dt_estimate()) {
    log.flush();
    std::cerr << "strata: warning: dt = " << scene.solver.dt << " s exceeds the stable estimate "
              << run->stable_dt_estimate() << " s of " << to_string(scene.solver.integrator)
              << "; the run will likely diverge\n";
  }
  log.flush();

  const OutputFolder output_folder(summary.output_dir);
  ProgressBar progress(options.progress, options.progress_file);
  std::filesystem::remove(summary.output_dir / "stats.json");  // this run's only, once it ends
  CsvSeries probes(summary.output_dir / "probes.csv", "time,probe,x,y,z,ux,uy,uz");
  ReactionRecorder reactions(summary.output_dir / "reactions.csv");
  std::optional<PvdWriter> pvd;
  if (scene.output.vtk) pvd.emplace(summary.output_dir / (scene.name + ".pvd"));
  double max_displacement = 0.0;
  const auto write_frame = [&]() {
    const double t = run->time();
    const VectorXd& x = run->positions();
    const VectorXd& v = run->velocities();
    const MatrixX3d positions = shown_points(x);
    const MatrixX3d displacement = positions - shown_rest;
    MatrixX3d velocity(positions.rows(), 3);
    if (binding) {
      velocity.topRows(shown_count) = deformed_velocities(*binding, body.triangles, x, v);
    } else {
      for (Index i = 0; i < S; ++i)
        velocity.row(i) = v.segment<3>(3 * i).transpose();
    }
    for (Index k = S; k < V; ++k)
      velocity.row(shown_count + k - S) = v.segment<3>(3 * k).transpose();
    max_displacement = std::max(max_displacement, displacement.rowwise().norm().maxCoeff());
    for (std::size_t p = 0; p < probe_points.size(); ++p) {
      std::ostringstream row;
      row << format_double(t) << ',' << p;
      for (int c = 0; c < 3; ++c)
        row << ',' << format_double(scene.output.probes[p][c]);
      for (int c = 0; c < 3; ++c)
        row << ',' << format_double(displacement(probe_points[p], c));
      probes.add_row(row.str());
    }
    reactions.record(t, run->reactions());
    if (pvd) {
      char name[48];
      std::snprintf(name, sizeof name, "_%06d.vtp", summary.frames);
      VtuFields surface_fields;
      surface_fields.add_point_data("displacement", displacement.topRows(shown_count));
      surface_fields.add_point_data("velocity", velocity.topRows(shown_count));
      write_vtp(summary.output_dir / (scene.name + name), positions.topRows(shown_count),
                shown.triangles, surface_fields, scene.output.vtk_encoding);
      pvd->add_frame(t, scene.name + name, 0);
    }
    if (pvd && scene.output.vtk_mesh) {
      char name[48];
      std::vector<std::array<int, 2>> lines;
      for (const auto& [a, b] : body.skeleton_segments)
        lines.push_back({static_cast<int>(a - S), static_cast<int>(b - S)});
      VtuFields skeleton_fields;
      skeleton_fields.add_point_data("displacement", displacement.bottomRows(V - S));
      std::snprintf(name, sizeof name, "_skeleton_%06d.vtp", summary.frames);
      write_vtp_lines(summary.output_dir / (scene.name + name), positions.bottomRows(V - S), lines,
                      skeleton_fields, scene.output.vtk_encoding);
      pvd->add_frame(t, scene.name + name, 1);
      if (simplified) {
        MatrixX3d spring_positions(S, 3), spring_displacement(S, 3);
        for (Index i = 0; i < S; ++i) {
          spring_positions.row(i) = x.segment<3>(3 * i).transpose();
          spring_displacement.row(i) = spring_positions.row(i) - body.rest.row(i);
        }
        VtuFields spring_fields;
        spring_fields.add_point_data("displacement", spring_displacement);
        std::snprintf(name, sizeof name, "_springs_%06d.vtp", summary.frames);
        write_vtp(summary.output_dir / (scene.name + name), spring_positions, body.triangles,
                  spring_fields, scene.output.vtk_encoding);
        pvd->add_frame(t, scene.name + name, 2);
      }
    }
    ++summary.frames;
  };
  const auto finish = [&]() {
    probes.save();
    reactions.csv().save();
    summary.steps = run->step_count();
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    summary.stable_dt_estimate = run->stable_dt_estimate();
    nlohmann::json stats;
    stats["status"] = summary.status;
    if (!summary.message.empty()) stats["message"] = summary.message;
    stats["scene"] = scene.file.string();
    stats["body"] = "skeleton_springs";
    stats["wall_seconds"] = summary.wall_seconds;
    stats["steps"] = summary.steps;
    stats["frames"] = summary.frames;
    stats["newton_iterations"] = run->newton_iterations();
    stats["substepped_steps"] = run->substepped_steps();
    stats["threads"] = max_threads();
    stats["huge_pages"] = huge_page_heap_state();
    stats["mode"] = "dynamic";
    stats["integrator"] = to_string(scene.solver.integrator);
    stats["dt"] = scene.solver.dt;
    stats["duration"] = scene.solver.duration;
    stats["final_time"] = run->time();
    stats["stable_dt_estimate"] = run->stable_dt_estimate();
    stats["vertices"] = V;
    stats["tets"] = 0;
    stats["dofs"] = 3 * V;
    stats["skeleton"] = {{"surface_vertices", S},
                         {"shown_surface_vertices", shown_count},
                         {"simplified", simplified},
                         {"simplify_seconds", simplify_seconds},
                         {"binding_max_distance", binding ? binding->distance.maxCoeff() : 0.0},
                         {"skeleton_points", V - S},
                         {"segments", body.skeleton_segments.size()},
                         {"seconds", skeleton.seconds},
                         {"springs",
                          {{"surface", body.count(SpringKind::surface)},
                           {"ties", body.count(SpringKind::tie)},
                           {"skeleton", body.count(SpringKind::skeleton)}}},
                         {"rule",
                          {{"shell_ratio", scene.body.rule.shell_ratio},
                           {"surface_scale", scene.body.rule.surface_scale},
                           {"tie_scale", scene.body.rule.tie_scale},
                           {"skeleton_scale", scene.body.rule.skeleton_scale}}},
                         {"mass", body.vertex_mass.sum()},
                         {"volume", body.volume}};
    stats["energies"] = {{"elastic", run->elastic_energy()},
                         {"kinetic", run->kinetic_energy()},
                         {"external_potential", run->external_potential_energy()}};
    stats["max_displacement"] = max_displacement;
    if (run->has_obstacles()) {
      const ContactSettings& contact = run->contact_settings();
      stats["contact"] = {{"max_penetration", run->max_penetration()},
                          {"tolerance", contact.distance},
                          {"barrier_stiffness", contact.stiffness},
                          {"friction_slip", contact.friction_slip},
                          {"points", S},
                          {"surface_points", S},
                          {"active_contacts", run->contact_counts()}};
    }
    stats["probes"] = scene.output.probes.size();
    write_file_atomically(summary.output_dir / "stats.json",
                          [&stats](std::ostream& out) { out << stats.dump(2) << '\n'; });
  };

  write_frame();
  try {
    while (!run->finished()) {
      run->advance();
      const long step = run->step_count();
      if (step % scene.output.every == 0 || run->finished()) {
        write_frame();
        probes.save_if_due();
        reactions.csv().save_if_due();
      }
      char label[64];
      std::snprintf(label, sizeof label, "t = %.4g s", run->time());
      progress.update(static_cast<double>(step) / static_cast<double>(total_steps), label);
    }
  } catch (const DivergenceError& error) {
    progress.clear();
    summary.status = "diverged";
    summary.message = error.what();
    finish();
    throw;
  }
  progress.clear();
  finish();
  if (!options.quiet)
    log << "strata: done: " << summary.steps << " steps, " << summary.frames << " frames in "
        << format_duration(summary.wall_seconds) << "; output in " << summary.output_dir.string()
        << "\n";
  return summary;
}

}  // namespace strata::app::detail
