#include "strata/app/mesh_command.hpp"

#include <algorithm>
#include <cctype>
#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/meshing/mesh_level_set.hpp"
#include "strata/meshing/mesh_surface_file.hpp"
#include "strata/meshing/surface_io.hpp"

namespace strata::app {

void run_mesh_command(const MeshCommand& command, std::ostream& log, std::ostream& warnings) {
  mesh_format_of(command.output);  // refuse an unknown output format before meshing
  TetMesh mesh;
  MeshingReport report;
  if (is_vdb_file(command.input)) {
    LevelSetMeshingResult result =
        mesh_level_set_file(command.input, command.grid, command.options);
    mesh = std::move(result.mesh);
    report = result.report;
  } else {
    if (!command.grid.empty()) {
      throw InputError(command.input.string() + ": --grid applies to .vdb input only");
    }
    SurfaceMeshingResult result = mesh_surface_file(command.input, command.options);
    if (!result.warning.empty()) warnings << "strata: warning: " << result.warning << std::endl;
    mesh = std::move(result.mesh);
    report = result.report;
  }
  write_tet_mesh(command.output, mesh);
  if (!command.quiet) {
    log << command.input.string() << " -> " << command.output.string() << "\n"
        << format_meshing_report(report) << std::flush;
  }
}

bool is_surface_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".off" || extension == ".obj" || extension == ".ply" || extension == ".stl";
}

void print_surface_info(const std::filesystem::path& path, std::ostream& out) {
  const SurfaceMesh surface = read_surface(path);
  out << path.string() << " (surface)\n"
      << format_surface_report(describe_surface(surface)) << std::flush;
}

void print_level_set_info(const std::filesystem::path& path, const std::string& grid,
                          std::ostream& out) {
  const LevelSet level_set = LevelSet::read_vdb(path, grid);
  out << path.string() << " (level set)\n" << format_level_set_report(level_set) << std::flush;
}

nlohmann::json meshing_stats_json(const MeshingReport& report) {
  const MeshQuality& q = report.quality;
  nlohmann::json json = {{"route", report.route},
                         {"from_cache", report.from_cache},
                         {"seconds", report.seconds},
                         {"tets", q.tets},
                         {"vertices", q.vertices},
                         {"boundary_faces", q.boundary_faces},
                         {"min_dihedral_angle_deg", q.min_dihedral_angle},
                         {"max_dihedral_angle_deg", q.max_dihedral_angle},
                         {"min_radius_ratio", q.min_radius_ratio},
                         {"mean_radius_ratio", q.mean_radius_ratio},
                         {"volume", q.total_volume}};
  if (report.surface_volume > 0.0) {
    json["surface_volume"] = report.surface_volume;
    json["volume_ratio"] = report.volume_ratio();
  }
  return json;
}

}  // namespace strata::app
