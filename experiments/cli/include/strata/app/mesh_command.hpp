#pragma once
/// \file mesh_command.hpp
/// `strata mesh` (surface or .vdb level set → tet mesh file) and the surface and level-set parts
/// of `strata info`.
#include <filesystem>
#include <iosfwd>
#include <string>

#include <nlohmann/json.hpp>

#include "strata/meshing/meshing_options.hpp"
#include "strata/meshing/meshing_report.hpp"

namespace strata::app {

/// Arguments of `strata mesh INPUT --cell-size H [...] --out OUT`.
struct MeshCommand {
  std::filesystem::path input;   ///< .off, .obj, .ply, .stl or .vdb
  std::filesystem::path output;  ///< .vtu, .mesh, .msh, .node (format from the extension)
  MeshingOptions options;
  std::string grid;    ///< .vdb input: the float grid to mesh; empty: the first float grid
  bool quiet = false;  ///< no report (warnings still print)
};

/// Meshes `command.input` (mesh_surface_file, or mesh_level_set_file for a .vdb; no cache), writes
/// `command.output` atomically and prints the meshing report to `log`, a non-watertight warning to
/// `warnings`. The output format is checked before meshing. InputError (one line naming the file)
/// on bad input.
void run_mesh_command(const MeshCommand& command, std::ostream& log, std::ostream& warnings);

/// True for the surface extensions read_surface accepts (.off, .obj, .ply, .stl, any case).
bool is_surface_file(const std::filesystem::path& path);

/// `strata info SURFACE`: the file name and format_surface_report.
void print_surface_info(const std::filesystem::path& path, std::ostream& out);

/// `strata info SHAPE.vdb [--grid NAME]`: the file name and format_level_set_report of the grid
/// (empty name: the first float grid).
void print_level_set_info(const std::filesystem::path& path, const std::string& grid,
                          std::ostream& out);

/// stats.json's "meshing" block: route, cache use, time, tet count, dihedral angles, radius
/// ratios, tet and surface volumes and their ratio.
nlohmann::json meshing_stats_json(const MeshingReport& report);

}  // namespace strata::app
