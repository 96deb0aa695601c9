#include <iostream>

#include "memory_check.hpp"
#include "strata/app/scene_runner.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/meshing/mesh_level_set.hpp"
#include "strata/meshing/mesh_surface_file.hpp"

namespace strata::app {

PreparedMesh prepare_scene_mesh(const Scene& scene) {
  const std::string where = scene.file.string() + ": mesh";
  PreparedMesh prepared;
  try {
    const MeshCache cache(mesh_cache_dir(scene));
    if (scene.mesh.surface) {
      SurfaceMeshingResult result =
          mesh_surface_file(*scene.mesh.surface, scene.mesh.meshing, &cache);
      if (!result.warning.empty()) std::cerr << "strata: warning: " << result.warning << std::endl;
      prepared.source = scene.mesh.surface->string();
      prepared.mesh = std::move(result.mesh);
      prepared.meshing = result.report;
    } else if (scene.mesh.level_set || scene.mesh.implicit) {
      LevelSetMeshingResult result =
          scene.mesh.level_set ? mesh_level_set_file(*scene.mesh.level_set, scene.mesh.grid,
                                                     scene.mesh.meshing, &cache)
                               : mesh_implicit_shape(*scene.mesh.implicit, scene.mesh.voxel_size,
                                                     scene.mesh.meshing, &cache);
      prepared.source = scene.mesh.level_set ? scene.mesh.level_set->string() : "implicit";
      prepared.mesh = std::move(result.mesh);
      prepared.meshing = result.report;
    } else if (scene.mesh.file) {
      prepared.source = scene.mesh.file->string();
      prepared.mesh = read_tet_mesh(*scene.mesh.file);
    } else {
      prepared.source = "box";
      const auto& cells = scene.mesh.box_cells;
      check_fits_in_memory(6.0 * cells[0] * cells[1] * cells[2], "cells");
      prepared.mesh = box_tet_mesh(scene.mesh.box_min, scene.mesh.box_max, scene.mesh.box_cells);
    }
    validate_tet_mesh(prepared.mesh, prepared.source);
  } catch (const InputError& error) {
    const char* key = scene.mesh.surface     ? ".surface: "
                      : scene.mesh.level_set ? ".level_set: "
                      : scene.mesh.implicit  ? ".implicit: "
                      : scene.mesh.file      ? ".file: "
                                             : ".box: ";
    throw InputError(where + key + error.what());
  }
  prepared.removed_vertices = remove_unreferenced_vertices(prepared.mesh);
  prepared.reoriented_tets = orient_tets(prepared.mesh);
  return prepared;
}

std::filesystem::path mesh_cache_dir(const Scene& scene) {
  return scene.file.parent_path() / "out" / "mesh_cache";
}

std::filesystem::path default_output_dir(const Scene& scene) {
  return scene.file.parent_path() / "out" / scene.name;
}

}  // namespace strata::app
