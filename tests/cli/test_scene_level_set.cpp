// Scenes with "mesh": {"level_set": ...} and {"implicit": ...}, `strata mesh SHAPE.vdb` and
// `strata info SHAPE.vdb`: parsing with key-path errors, meshed volumes against closed forms, the
// support reaction against ρ V g of the written mesh, .vdb against primitive, cache reuse, and bad
// input (exit code 2, one line naming the key).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cli_test_utils.hpp"
#include "strata/app/scene_parser.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/meshing/level_set.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kPi = 3.14159265358979323846;

/// A static scene under gravity, fixed below z = −0.8 (the cap of the unit ball at the origin).
json ball_scene(const json& mesh) {
  json scene = json::parse(R"({
    "material": {"model": "neohookean", "youngs_modulus": 1e8, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [-2, -2, -2], "max": [2, 2, -0.8]}}],
    "solver": {"mode": "static", "load_steps": 1, "newton_tolerance": 1e-8}
  })");
  scene["mesh"] = mesh;
  return scene;
}

/// cell 0.4, facet distance 0.03, no optimisation: a few hundred tets.
json ball_mesh_keys(json mesh) {
  mesh["cell_size"] = 0.4;
  mesh["facet_distance"] = 0.03;
  mesh["perturb"] = false;
  mesh["exude"] = false;
  return mesh;
}

const json kUnitBall = json::parse(R"({"sphere": {"center": [0, 0, 0], "radius": 1}})");

std::string parse_error(const json& scene) {
  try {
    app::parse_scene(scene, "dir/scene.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

/// Σ det[x1 − x0, x2 − x0, x3 − x0] / 6 over the tets of a mesh file.
double volume_of_mesh_file(const std::filesystem::path& path) {
  const TetMesh mesh = read_tet_mesh(path);
  double volume = 0.0;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    Matrix3d edges;
    for (int k = 0; k < 3; ++k)
      edges.col(k) =
          (mesh.vertices.row(mesh.tets(t, k + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
    volume += edges.determinant() / 6.0;
  }
  return volume;
}

/// The only entry of the scene's mesh cache.
std::filesystem::path cache_entry(const std::filesystem::path& folder) {
  std::filesystem::path entry;
  int count = 0;
  for (const auto& file : std::filesystem::directory_iterator(folder / "out" / "mesh_cache")) {
    entry = file.path();
    ++count;
  }
  EXPECT_EQ(count, 1);
  return entry;
}

TEST(SceneLevelSet, ParsesShapesAndLevelSets) {
  const json mesh = json::parse(R"({"implicit": {"union": [
      {"sphere": {"center": [0, 0, 0], "radius": 1}},
      {"difference": [{"box": {"min": [0, 0, 0], "max": [1, 2, 3]}},
                      {"capsule": {"a": [0, 0, 0], "b": [1, 0, 0], "radius": 0.5}}]},
      {"intersection": [{"torus": {"center": [1, 1, 1], "major_radius": 2,
                                   "minor_radius": 0.5}},
                        {"torus": {"center": [0, 0, 0], "axis": [0, 3, 0], "major_radius": 1,
                                   "minor_radius": 0.25}}]}]},
    "cell_size": 0.2, "voxel_size": 0.01, "facet_angle": 20})");
  const app::Scene scene = app::parse_scene(ball_scene(mesh), "dir/scene.json");
  ASSERT_TRUE(scene.mesh.implicit.has_value());
  EXPECT_FALSE(scene.mesh.surface || scene.mesh.level_set || scene.mesh.file);
  EXPECT_DOUBLE_EQ(scene.mesh.voxel_size, 0.01);
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.cell_size, 0.2);
  EXPECT_DOUBLE_EQ(scene.mesh.meshing.facet_angle, 20.0);
  EXPECT_EQ(describe_implicit_shape(*scene.mesh.implicit),
            "union(sphere([0,0,0],1),difference(box([0,0,0],[1,2,3]),capsule([0,0,0],[1,0,0],0.5)),"
            "intersection(torus([1,1,1],[0,0,1],2,0.5),torus([0,0,0],[0,1,0],1,0.25)))");

  const app::Scene vdb = app::parse_scene(
      ball_scene({{"level_set", "shape.vdb"}, {"grid", "ball"}, {"cell_size", 0.3}}),
      "dir/scene.json");
  ASSERT_TRUE(vdb.mesh.level_set.has_value());
  EXPECT_EQ(*vdb.mesh.level_set, std::filesystem::path("dir") / "shape.vdb");
  EXPECT_EQ(vdb.mesh.grid, "ball");
  EXPECT_DOUBLE_EQ(vdb.mesh.meshing.cell_size, 0.3);
}

TEST(SceneLevelSet, DemoSceneParses) {
  const app::Scene scene = app::load_scene(
      std::filesystem::path(STRATA_SOURCE_DIR) / "experiments" / "scenes" / "csg_ring.json", {});
  ASSERT_TRUE(scene.mesh.implicit.has_value());
  EXPECT_EQ(
      describe_implicit_shape(*scene.mesh.implicit),
      "difference(union(torus([0,0,0],[0,0,1],0.10000000000000001,0.029999999999999999),"
      "capsule([-0.12,0,0],[0.12,0,0],0.02)),box([-0.20000000000000001,-0.20000000000000001,"
      "0.014999999999999999],[0.20000000000000001,0.20000000000000001,0.20000000000000001]))");
}

TEST(SceneLevelSet, ParserErrorsNameTheKeyPath) {
  const auto implicit = [](const char* shape) {
    return ball_scene({{"implicit", json::parse(shape)}, {"cell_size", 0.3}});
  };
  EXPECT_EQ(parse_error(implicit(R"({"union": [{"sphere": {"center": [0,0,0], "radius": 1}},
                                               {"sphere": {"center": [1,0,0], "radius": -1}}]})")),
            "dir/scene.json: mesh.implicit.union.1.sphere.radius: must be > 0");
  EXPECT_EQ(parse_error(implicit(R"({"union": []})")),
            "dir/scene.json: mesh.implicit.union: must list at least 1 shape");
  EXPECT_EQ(parse_error(implicit(R"({"intersection": []})")),
            "dir/scene.json: mesh.implicit.intersection: must list at least 1 shape");
  EXPECT_EQ(parse_error(implicit(R"({"difference": [{"box": {"min": [0,0,0], "max": [1,1,1]}}]})")),
            "dir/scene.json: mesh.implicit.difference: must list exactly 2 shapes (the first minus "
            "the second), got 1");
  EXPECT_EQ(parse_error(implicit(R"({"sphere": {"center": [0,0,0], "radius": 1},
                                     "box": {"min": [0,0,0], "max": [1,1,1]}})")),
            "dir/scene.json: mesh.implicit: must have exactly one of sphere, box, capsule, torus, "
            "union, intersection, difference");
  EXPECT_EQ(parse_error(implicit(R"({"cone": {}})")),
            "dir/scene.json: mesh.implicit.cone: unknown key");
  EXPECT_EQ(parse_error(implicit(R"({"box": {"min": [0,0,0], "max": [1,0,1]}})")),
            "dir/scene.json: mesh.implicit.box.max: must be > min in every coordinate");
  EXPECT_EQ(parse_error(implicit(R"({"torus": {"center": [0,0,0], "axis": [0,0,0],
                                               "major_radius": 1, "minor_radius": 0.1}})")),
            "dir/scene.json: mesh.implicit.torus.axis: must not be the zero vector");
  EXPECT_EQ(parse_error(implicit(R"({"capsule": {"a": [0,0,0], "b": [1,0,0]}})")),
            "dir/scene.json: mesh.implicit.capsule.radius: missing required key");
  EXPECT_EQ(
      parse_error(ball_scene({{"implicit", kUnitBall}, {"cell_size", 0.3}, {"voxel_size", 0}})),
      "dir/scene.json: mesh.voxel_size: must be > 0");
  EXPECT_EQ(
      parse_error(ball_scene({{"level_set", "a.vdb"}, {"cell_size", 0.3}, {"voxel_size", 0.1}})),
      "dir/scene.json: mesh.voxel_size: only allowed with implicit");
  EXPECT_EQ(parse_error(ball_scene({{"implicit", kUnitBall}, {"cell_size", 0.3}, {"grid", "g"}})),
            "dir/scene.json: mesh.grid: only allowed with level_set");
  EXPECT_EQ(parse_error(ball_scene({{"level_set", "a.vdb"}})),
            "dir/scene.json: mesh.cell_size: missing required key");
  EXPECT_EQ(parse_error(
                ball_scene({{"level_set", "a.vdb"}, {"implicit", kUnitBall}, {"cell_size", 0.3}})),
            "dir/scene.json: mesh: must have exactly one of file, box, surface, level_set, "
            "implicit");
}

TEST(SceneLevelSet, SphereSceneMeshesTheBallAndCarriesItsWeight) {
  TempFolder folder;
  write_text(folder.path() / "scene.json",
             ball_scene(ball_mesh_keys({{"implicit", kUnitBall}})).dump(2));
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json stats = read_json(folder.path() / "out" / "scene" / "stats.json");
  ASSERT_TRUE(stats.contains("meshing")) << stats.dump(2);
  EXPECT_EQ(stats["meshing"]["route"], "level set");
  EXPECT_EQ(stats["meshing"]["from_cache"], false);
  EXPECT_EQ(stats["mesh_source"], "implicit");
  // Boundary facets within δ = 0.03 of the unit sphere: volume deficit below 3δ/r · V.
  const double ball = 4.0 / 3.0 * kPi;
  const double volume = volume_of_mesh_file(cache_entry(folder.path()));
  EXPECT_NEAR(volume, ball, 3.0 * 0.03 * ball);
  EXPECT_NEAR(stats["meshing"]["volume"].get<double>(), volume, 1e-9 * volume);
  EXPECT_NEAR(stats["meshing"]["surface_volume"].get<double>(), ball, 0.02 * ball);
  // Static equilibrium: the support carries the weight ρ V g of the meshed volume.
  const Csv reactions = read_csv(folder.path() / "out" / "scene" / "reactions.csv");
  ASSERT_FALSE(reactions.rows.empty());
  EXPECT_NEAR(reactions.rows.back()[4], 1000.0 * volume * 9.81, 1e-6 * 1000.0 * volume * 9.81);
  EXPECT_NEAR(reactions.rows.back()[2], 0.0, 1e-6 * 1000.0 * volume * 9.81);

  const CliResult again = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(read_json(folder.path() / "out" / "scene" / "stats.json")["meshing"]["from_cache"],
            true);
  const CliResult info = run_strata("info scene.json", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("(mesh generated from implicit)"));
  EXPECT_THAT(info.out, HasSubstr("meshing           level set, from the cache"));
}

TEST(SceneLevelSet, VdbSceneMeshesLikeThePrimitiveAndUsesTheCache) {
  TempFolder folder;
  // The grid the implicit scene builds: default voxels facet size / 4 = 0.1.
  LevelSetOptions options;
  options.voxel_size = 0.1;
  level_set_sphere(Vector3d::Zero(), 1.0, options).write_vdb(folder.path() / "ball.vdb");
  write_text(folder.path() / "primitive.json",
             ball_scene(ball_mesh_keys({{"implicit", kUnitBall}})).dump(2));
  write_text(folder.path() / "vdb.json",
             ball_scene(ball_mesh_keys({{"level_set", "ball.vdb"}, {"grid", "sphere"}})).dump(2));
  ASSERT_EQ(run_strata("run primitive.json --quiet", folder.path()).exit_code, 0);
  const std::filesystem::path primitive_entry = cache_entry(folder.path());
  const TetMesh primitive = read_tet_mesh(primitive_entry);
  std::filesystem::rename(primitive_entry, folder.path() / "primitive.vtu");

  CliResult result = run_strata("run vdb.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  json stats = read_json(folder.path() / "out" / "vdb" / "stats.json");
  EXPECT_EQ(stats["meshing"]["from_cache"], false);
  EXPECT_EQ(stats["mesh_source"], "ball.vdb");
  const TetMesh from_vdb = read_tet_mesh(cache_entry(folder.path()));
  EXPECT_EQ(from_vdb.tets, primitive.tets);
  EXPECT_EQ(from_vdb.vertices, primitive.vertices);
  const json primitive_stats = read_json(folder.path() / "out" / "primitive" / "stats.json");
  EXPECT_EQ(stats["max_displacement"], primitive_stats["max_displacement"]);

  result = run_strata("run vdb.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  stats = read_json(folder.path() / "out" / "vdb" / "stats.json");
  EXPECT_EQ(stats["meshing"]["from_cache"], true);
  EXPECT_EQ(stats["max_displacement"], primitive_stats["max_displacement"]);
}

TEST(SceneLevelSet, MeshAndInfoCommandsReadVdbFiles) {
  TempFolder folder;
  LevelSetOptions options;
  options.voxel_size = 0.1;
  level_set_sphere(Vector3d(1, 0, 0), 1.0, options).write_vdb(folder.path() / "ball.vdb");
  CliResult info = run_strata("info ball.vdb", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, StartsWith("ball.vdb (level set)\n"));
  EXPECT_THAT(info.out, HasSubstr("grid              sphere\n"));
  EXPECT_THAT(info.out, HasSubstr("voxel size        0.1\n"));
  // Active voxels: centres (multiples of 0.1) with |φ| below the band of 3 voxels, i.e. up to 2
  // voxels beyond the sphere.
  EXPECT_THAT(info.out, HasSubstr("bounding box      [-0.2, -1.2, -1.2] .. [2.2, 1.2, 1.2]\n"));
  EXPECT_THAT(info.out, HasSubstr("active voxels     "));

  const CliResult mesh = run_strata(
      "mesh ball.vdb --grid sphere --cell-size 0.4 --facet-distance 0.03 --no-optimize --out "
      "ball.vtu",
      folder.path());
  ASSERT_EQ(mesh.exit_code, 0) << mesh.err;
  EXPECT_THAT(mesh.out, HasSubstr("meshing           level set"));
  const double ball = 4.0 / 3.0 * kPi;
  EXPECT_NEAR(volume_of_mesh_file(folder.path() / "ball.vtu"), ball, 3.0 * 0.03 * ball);

  const CliResult wrong = run_strata("info ball.vdb --grid nothere", folder.path());
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_THAT(wrong.err, HasSubstr("no grid named 'nothere'"));
  const CliResult grid_on_surface =
      run_strata("mesh ball.off --grid sphere --cell-size 0.4 --out m.vtu", folder.path());
  EXPECT_EQ(grid_on_surface.exit_code, 2);
  EXPECT_THAT(grid_on_surface.err, HasSubstr("--grid applies to .vdb input only"));
}

TEST(SceneLevelSet, BadInputExitsWithTheKeyPath) {
  TempFolder folder;
  LevelSetOptions options;
  options.voxel_size = 0.1;
  level_set_sphere(Vector3d::Zero(), 1.0, options).write_vdb(folder.path() / "ball.vdb");
  const struct {
    json mesh;
    std::string message;
  } cases[] = {
      {ball_mesh_keys({{"level_set", "missing.vdb"}}),
       "scene.json: mesh.level_set: cannot read 'missing.vdb': no such file"},
      {ball_mesh_keys({{"level_set", "ball.vdb"}, {"grid", "nothere"}}),
       "scene.json: mesh.level_set: cannot read 'ball.vdb': no grid named 'nothere'"},
      {ball_mesh_keys({{"implicit", json::parse(R"({"union": []})")}}),
       "scene.json: mesh.implicit.union: must list at least 1 shape"},
      {ball_mesh_keys({{"implicit",
                        json::parse(R"({"difference": [{"sphere": {"center": [0,0,0], "radius": 1}},
              {"sphere": {"center": [0,0,0], "radius": 0.5}},
              {"sphere": {"center": [0,0,0], "radius": 0.2}}]})")}}),
       "scene.json: mesh.implicit.difference: must list exactly 2 shapes (the first minus the "
       "second), got 3"},
      {ball_mesh_keys({{"implicit", json::parse(R"({"union": [
              {"sphere": {"center": [0,0,0], "radius": 1}},
              {"sphere": {"center": [0,0,0], "radius": -0.5}}]})")}}),
       "scene.json: mesh.implicit.union.1.sphere.radius: must be > 0"},
      {ball_mesh_keys({{"implicit", json::parse(R"({"intersection": [
              {"sphere": {"center": [0,0,0], "radius": 0.5}},
              {"sphere": {"center": [3,0,0], "radius": 0.5}}]})")}}),
       "scene.json: mesh.implicit: level set 'sphere_intersection_sphere' encloses no volume"},
  };
  for (const auto& c : cases) {
    write_text(folder.path() / "scene.json", ball_scene(c.mesh).dump(2));
    const CliResult result = run_strata("run scene.json --quiet", folder.path());
    EXPECT_EQ(result.exit_code, 2) << c.mesh.dump();
    EXPECT_EQ(result.err, "strata: error: " + c.message + "\n") << c.mesh.dump();
  }
}

}  // namespace
}  // namespace strata::cli_test
