// Scene key "mesh": {"surface": ..., Mesh_3 parameters}: values, defaults and key-path errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "strata/app/scene_parser.hpp"
#include "strata/core/common/error.hpp"

namespace strata::app {
namespace {

using nlohmann::json;

json surface_scene(const json& mesh) {
  json scene = json::parse(R"({
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "fixed": [{"box": {"min": [0, 0, 0], "max": [0, 0.1, 0.1]}}],
    "solver": {"mode": "static"}
  })");
  scene["mesh"] = mesh;
  return scene;
}

std::string parse_error(const json& scene) {
  try {
    parse_scene(scene, "dir/scene.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SceneMeshSpec, SurfaceWithDefaults) {
  const Scene scene =
      parse_scene(surface_scene({{"surface", "bunny.off"}, {"cell_size", 0.05}}), "dir/s.json");
  ASSERT_TRUE(scene.mesh.surface.has_value());
  EXPECT_EQ(*scene.mesh.surface, std::filesystem::path("dir") / "bunny.off");
  EXPECT_FALSE(scene.mesh.file.has_value());
  const MeshingOptions defaults;
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.cell_size, 0.05);
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.facet_size, defaults.facet_size);
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.facet_angle, defaults.facet_angle);
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.cell_radius_edge_ratio, defaults.cell_radius_edge_ratio);
  EXPECT_EQ(scene.mesh.meshing.sharp_features, defaults.sharp_features);
  EXPECT_EQ(scene.mesh.meshing.seed, defaults.seed);
}

TEST(SceneMeshSpec, AllMeshingKeys) {
  const json mesh = json::parse(R"({"surface": "/abs/part.stl", "cell_size": 0.1,
    "facet_size": 0.2, "facet_distance": 0.01, "facet_angle": 20, "radius_edge_ratio": 2.5,
    "sharp_features": true, "perturb": false, "exude": false, "odt": true, "lloyd": true,
    "seed": 7})");
  const Scene scene = parse_scene(surface_scene(mesh), "dir/s.json");
  EXPECT_EQ(*scene.mesh.surface, std::filesystem::path("/abs/part.stl"));
  const MeshingOptions& options = scene.mesh.meshing;
  EXPECT_DOUBLE_EQ(options.cell_size, 0.1);
  EXPECT_DOUBLE_EQ(options.facet_size, 0.2);
  EXPECT_DOUBLE_EQ(options.facet_distance, 0.01);
  EXPECT_DOUBLE_EQ(options.facet_angle, 20.0);
  EXPECT_DOUBLE_EQ(options.cell_radius_edge_ratio, 2.5);
  EXPECT_TRUE(options.sharp_features);
  EXPECT_FALSE(options.perturb);
  EXPECT_FALSE(options.exude);
  EXPECT_TRUE(options.odt);
  EXPECT_TRUE(options.lloyd);
  EXPECT_EQ(options.seed, 7u);
}

TEST(SceneMeshSpec, ErrorsNameTheKey) {
  EXPECT_EQ(parse_error(surface_scene({{"surface", "a.off"}})),
            "dir/scene.json: mesh.cell_size: missing required key");
  EXPECT_EQ(parse_error(surface_scene({{"surface", "a.off"}, {"cell_size", 0}})),
            "dir/scene.json: mesh.cell_size: must be > 0");
  EXPECT_EQ(parse_error(surface_scene({{"surface", ""}, {"cell_size", 1}})),
            "dir/scene.json: mesh.surface: must not be empty");
  EXPECT_EQ(
      parse_error(surface_scene({{"surface", "a.off"}, {"cell_size", 1}, {"facet_angle", 45}})),
      "dir/scene.json: mesh.facet_angle: must be in (0, 30] degrees (Mesh_3 need not terminate "
      "above 30)");
  EXPECT_EQ(parse_error(surface_scene(
                {{"surface", "a.off"}, {"cell_size", 1}, {"radius_edge_ratio", 1.5}})),
            "dir/scene.json: mesh.radius_edge_ratio: must be >= 2 (Mesh_3 need not terminate "
            "below 2)");
  EXPECT_EQ(parse_error(surface_scene({{"surface", "a.off"}, {"cell_size", 1}, {"seed", -1}})),
            "dir/scene.json: mesh.seed: must be >= 0");
  EXPECT_EQ(
      parse_error(surface_scene({{"surface", "a.off"}, {"file", "b.msh"}})),
      "dir/scene.json: mesh: must have exactly one of file, box, surface, level_set, implicit");
  EXPECT_EQ(
      parse_error(surface_scene(json::object())),
      "dir/scene.json: mesh: must have exactly one of file, box, surface, level_set, implicit");
  EXPECT_EQ(
      parse_error(surface_scene({{"file", "b.msh"}, {"cell_size", 1}})),
      "dir/scene.json: mesh.cell_size: is a meshing key: only allowed with surface, level_set, "
      "implicit");
  EXPECT_EQ(parse_error(surface_scene({{"surface", "a.off"}, {"cell_size", 1}, {"cells", 1}})),
            "dir/scene.json: mesh.cells: unknown key");
}

}  // namespace
}  // namespace strata::app
