#include "strata/app/scene_runner.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"

namespace strata::app {

PreparedMesh prepare_scene_mesh(const Scene& scene) {
  const std::string where = scene.file.string() + ": mesh";
  PreparedMesh prepared;
  try {
    if (scene.mesh.surface) {
      throw InputError(scene.mesh.surface->string() +
                       ": tetrahedralising a surface is not available yet");
    } else if (scene.mesh.file) {
      prepared.source = scene.mesh.file->string();
      prepared.mesh = read_tet_mesh(*scene.mesh.file);
    } else {
      prepared.source = "box";
      prepared.mesh = box_tet_mesh(scene.mesh.box_min, scene.mesh.box_max, scene.mesh.box_cells);
    }
    validate_tet_mesh(prepared.mesh, prepared.source);
  } catch (const InputError& error) {
    const char* key = scene.mesh.surface ? ".surface: " : scene.mesh.file ? ".file: " : ".box: ";
    throw InputError(where + key + error.what());
  }
  prepared.removed_vertices = remove_unreferenced_vertices(prepared.mesh);
  prepared.reoriented_tets = orient_tets(prepared.mesh);
  return prepared;
}

std::filesystem::path default_output_dir(const Scene& scene) {
  return scene.file.parent_path() / "out" / scene.name;
}

}  // namespace strata::app
