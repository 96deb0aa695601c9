// strata: run scenes, inspect and convert tet meshes. Exit codes: 0 ok, 2 bad input, 3 diverged.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "strata/app/huge_pages.hpp"
#include "strata/app/mesh_command.hpp"
#include "strata/app/precompute_command.hpp"
#include "strata/app/progress_bar.hpp"
#include "strata/app/scene_parser.hpp"
#include "strata/app/scene_runner.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/meshing/mesh_level_set.hpp"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitDiverged = 3;

/// `text` read whole by `parse` (std::stol, std::stod), or nothing.
template <typename T, typename Parse>
std::optional<T> read_whole(const std::string& text, Parse parse) {
  try {
    std::size_t used = 0;
    const T value = parse(text, &used);
    if (!text.empty() && used == text.size()) return value;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

/// A whole number in [minimum, maximum]; the message quotes the bounds as integers.
CLI::Validator whole_number(long minimum, long maximum) {
  return CLI::Validator(
      [minimum, maximum](std::string& text) -> std::string {
        const std::optional<long> value = read_whole<long>(
            text, [](const std::string& t, std::size_t* used) { return std::stol(t, used); });
        if (!value) return "expected a whole number, got '" + text + "'";
        if (*value < minimum || *value > maximum)
          return "must be between " + std::to_string(minimum) + " and " + std::to_string(maximum) +
                 ", got " + text;
        return {};
      },
      "INT in [" + std::to_string(minimum) + ", " + std::to_string(maximum) + "]");
}

/// A number strictly between 0 and 1.
CLI::Validator open_unit_interval() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::optional<double> value = read_whole<double>(
            text, [](const std::string& t, std::size_t* used) { return std::stod(t, used); });
        if (!value) return "expected a number, got '" + text + "'";
        if (!(*value > 0.0 && *value < 1.0)) return "must be in (0, 1), got " + text;
        return {};
      },
      "in (0, 1)");
}

/// One line whatever the message holds: control characters (a newline or NUL inside a key, a
/// value or a file name the message quotes) are written as escapes.
std::string one_line(const std::string& message) {
  std::string line;
  for (const char c : message) {
    if (c == '\n') {
      line += "\\n";
    } else if (c == '\r') {
      line += "\\r";
    } else if (c == '\t') {
      line += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", static_cast<unsigned char>(c));
      line += escaped;
    } else {
      line += c;
    }
  }
  return line;
}

int fail(const std::string& message, int code) {
  std::cerr << "strata: error: " << one_line(message) << std::endl;
  return code;
}

/// `strata info`: counts, volume and quality of a mesh file, or of a scene's mesh.
int run_info(const std::filesystem::path& path, const std::string& grid) {
  if (strata::is_vdb_file(path)) {
    strata::app::print_level_set_info(path, grid, std::cout);
    return kExitOk;
  }
  if (!grid.empty())
    throw strata::InputError(path.string() + ": --grid applies to .vdb files only");
  if (strata::app::is_surface_file(path)) {
    strata::app::print_surface_info(path, std::cout);
    return kExitOk;
  }
  strata::TetMesh mesh;
  std::string source = path.string();
  if (path.extension() == ".json") {
    const strata::app::Scene scene = strata::app::load_scene(path, {});
    strata::app::PreparedMesh prepared = strata::app::prepare_scene_mesh(scene);
    if (prepared.meshing) {
      std::cout << path.string() << " (mesh generated from " << prepared.source << ")\n"
                << strata::format_meshing_report(*prepared.meshing) << std::flush;
      return kExitOk;
    }
    mesh = std::move(prepared.mesh);
    source += " (mesh " + prepared.source + ")";
  } else {
    mesh = strata::read_tet_mesh(path);
  }
  const strata::Index num_vertices = mesh.vertices.rows();
  for (strata::Index t = 0; t < mesh.tets.rows(); ++t) {
    for (int k = 0; k < 4; ++k) {
      if (mesh.tets(t, k) < 0 || mesh.tets(t, k) >= num_vertices) {
        throw strata::InputError(path.string() + ": tet " + std::to_string(t) +
                                 " has a vertex index out of range");
      }
    }
  }
  std::cout << source << "\n"
            << strata::format_mesh_quality(strata::compute_mesh_quality(mesh)) << std::flush;
  strata::validate_tet_mesh(mesh, path.string());
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  // Runs build large matrices once: they start on a heap of huge pages (huge_pages.hpp).
  if (argc > 1 && (std::string(argv[1]) == "run" || std::string(argv[1]) == "precompute"))
    strata::app::use_huge_page_heap(argv);
  CLI::App app{"strata: tetrahedral FEM simulation of deformable solids", "strata"};
  app.set_version_flag("--version", STRATA_VERSION);
  app.require_subcommand(1);

  CLI::App* run = app.add_subcommand("run", "Run a scene file and write its outputs");
  run->footer(
      "Environment: STRATA_HUGE_PAGES=0 keeps the heap on small pages (by default run restarts "
      "itself once with GLIBC_TUNABLES=glibc.malloc.hugetlb=1; README, Huge pages).");
  std::string scene_file;
  std::string out_dir;
  std::vector<std::string> overrides;
  bool quiet = false;
  run->add_option("scene", scene_file, "Scene file (JSON)")->required();
  run->add_option("--out", out_dir, "Output folder (default: <scene folder>/out/<scene name>)");
  run->add_option("--set", overrides,
                  "Override a scene key: key.path=value (value as JSON, else a string); "
                  "repeatable, e.g. --set solver.dt=1e-4 --set fixed.0.box.max=[0,1,1]")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  run->add_flag("-q,--quiet", quiet, "No progress bar, info lines or summary");
  std::string progress_file;
  run->add_option("--progress-file", progress_file,
                  "Rewrite this file with '<fraction done> <seconds elapsed>' as the run goes "
                  "(at most twice a second), for programs that watch the run");
  int threads = 0;
  run->add_option("--threads", threads,
                  "Threads of strata's parallel loops (default 0: every core); the BLAS and "
                  "OpenMP threads of the sparse solver stay at 1 so that nothing oversubscribes")
      ->check(whole_number(0, 4096));

  CLI::App* info = app.add_subcommand("info", "Print counts, volume and quality of a tet mesh");
  std::string info_file;
  std::string info_grid;
  info->add_option("mesh", info_file,
                   "Mesh file (.msh, .mesh, .node/.ele, .vtu), surface, level set (.vdb) or "
                   "scene (.json)")
      ->required();
  info->add_option("--grid", info_grid, "Grid of a .vdb (default: its first float grid)");

  strata::app::MeshCommand mesh_command;
  CLI::App* mesh = app.add_subcommand(
      "mesh", "Tetrahedralise a surface (.off, .obj, .ply, .stl) or a level set (.vdb)");
  mesh->add_option("input", mesh_command.input, "Surface or level-set file")->required();
  mesh->add_option("--grid", mesh_command.grid, "Grid of a .vdb (default: its first float grid)");
  mesh->add_option("--out", mesh_command.output, "Tet mesh file (.vtu, .mesh, .msh, .node)")
      ->required();
  strata::MeshingOptions& meshing = mesh_command.options;
  mesh->add_option("--cell-size", meshing.cell_size, "Max tet circumradius")->required();
  mesh->add_option("--facet-size", meshing.facet_size,
                   "Max surface facet circumradius (default: cell size)");
  mesh->add_option("--facet-distance", meshing.facet_distance,
                   "Max facet-to-surface distance (default: cell size / 10)");
  mesh->add_option("--facet-angle", meshing.facet_angle, "Min facet angle [deg], <= 30")
      ->capture_default_str();
  mesh->add_option("--radius-edge", meshing.cell_radius_edge_ratio,
                   "Max tet radius-edge ratio, >= 2")
      ->capture_default_str();
  mesh->add_flag("--sharp-features", meshing.sharp_features, "Protect sharp edges of the surface");
  mesh->add_flag("!--no-optimize", meshing.perturb, "Skip sliver perturbation and exudation");
  mesh->add_flag("--odt", meshing.odt, "ODT smoothing");
  mesh->add_flag("--lloyd", meshing.lloyd, "Lloyd smoothing");
  mesh->add_option("--seed", meshing.seed, "Random seed")->capture_default_str();
  mesh->add_flag("-q,--quiet", mesh_command.quiet, "No report");

  CLI::App* convert = app.add_subcommand("convert", "Convert a tet mesh between file formats");
  std::string convert_in, convert_out;
  convert->add_option("input", convert_in, "Input mesh file")->required();
  convert->add_option("output", convert_out, "Output mesh file (format from the extension)")
      ->required();

  strata::app::PrecomputeCommand precompute_command;
  CLI::App* precompute = app.add_subcommand(
      "precompute",
      "Run scenes adaptively and write the cut they needed, for hierarchy mode \"precomputed\"");
  precompute->add_option("scenes", precompute_command.scenes, "Scene files (same mesh and levels)")
      ->required();
  precompute->add_option("--out", precompute_command.output, "Cut file to write (.json)")
      ->required();
  precompute->add_option("--mesh", precompute_command.mesh,
                         "Also write the cut as a conforming tet mesh (.vtu, .mesh, .msh, .node)");
  precompute
      ->add_option("--tolerance", precompute_command.tolerance,
                   "hierarchy.tolerance of the recorded runs (default: half of each scene's)")
      ->check(open_unit_interval());
  precompute
      ->add_option("--windows", precompute_command.windows,
                   "Cuts in the schedule: equal windows of the run's time (default 1: one cut; at "
                   "most the longest run's steps)")
      ->check(whole_number(1, 1000000));
  precompute
      ->add_option("--set", precompute_command.overrides,
                   "Override a key of every scene: key.path=value (as for run)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  precompute->add_flag("-q,--quiet", precompute_command.quiet, "No info lines");
  precompute->add_option("--threads", threads, "Threads of strata's parallel loops (as for run)")
      ->check(whole_number(0, 4096));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& error) {
    return app.exit(error);
  } catch (const CLI::CallForAllHelp& error) {
    return app.exit(error);
  } catch (const CLI::CallForVersion& error) {
    return app.exit(error);
  } catch (const CLI::ParseError& error) {
    return fail(error.what(), kExitBadInput);
  }

  try {
    strata::set_thread_policy({.threads = threads});
    if (*run) {
      if (run->count("--out") > 0 && out_dir.empty())
        throw strata::InputError("--out: the output folder must not be empty");
      const strata::app::Scene scene = strata::app::load_scene(scene_file, overrides);
      strata::app::RunOptions options;
      options.output_dir = out_dir;
      options.quiet = quiet;
      options.progress = !quiet && strata::app::stderr_is_terminal();
      options.progress_file = progress_file;
      strata::app::run_scene(scene, options);
    } else if (*precompute) {
      precompute_command.progress = !precompute_command.quiet && strata::app::stderr_is_terminal();
      strata::app::run_precompute_command(precompute_command, std::cout);
    } else if (*info) {
      return run_info(info_file, info_grid);
    } else if (*mesh) {
      mesh_command.options.exude = mesh_command.options.perturb;
      strata::app::run_mesh_command(mesh_command, std::cout, std::cerr);
    } else if (*convert) {
      strata::convert_tet_mesh(convert_in, convert_out);
      std::cout << "strata: wrote " << convert_out << std::endl;
    }
  } catch (const strata::DivergenceError& error) {
    return fail(error.what(), kExitDiverged);
  } catch (const strata::InputError& error) {
    return fail(error.what(), kExitBadInput);
  } catch (const std::filesystem::filesystem_error& error) {
    return fail(error.what(), kExitBadInput);
  } catch (const std::bad_alloc&) {
    return fail(
        "out of memory: the scene needs more memory than the machine gives (a finer mesh, more "
        "hierarchy levels or a smaller voxel_size than it can hold)",
        kExitBadInput);
  } catch (const std::exception& error) {
    return fail(std::string("internal error: ") + error.what(), 1);
  }
  return kExitOk;
}
