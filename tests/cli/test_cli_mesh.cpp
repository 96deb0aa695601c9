// `strata mesh`, `strata info` on surfaces, and scenes with "mesh": {"surface": ...}: outputs,
// cache reuse, stats.json's meshing block and bad input (one line, exit code 2).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cli_test_utils.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

/// The unit cube as 6 outward quads (OFF).
const char* const kCubeOff =
    "OFF\n8 6 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
    "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";

int count_lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(CliMesh, MeshesASurfaceAndInfoReadsTheResult) {
  TempFolder folder;
  write_text(folder.path() / "cube.off", kCubeOff);
  const CliResult result =
      run_strata("mesh cube.off --cell-size 0.3 --sharp-features --out cube.vtu", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("meshing           polyhedral"));
  EXPECT_THAT(result.out, HasSubstr("tet / surface volume 1.000000"));
  ASSERT_TRUE(std::filesystem::exists(folder.path() / "cube.vtu"));
  const CliResult info = run_strata("info cube.vtu", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("volume            1 "));
  EXPECT_THAT(info.out, HasSubstr("inverted tets     0"));
  // Same seed, same mesh: a second run writes an identical file.
  ASSERT_EQ(
      run_strata("mesh cube.off --cell-size 0.3 --sharp-features -q --out again.vtu", folder.path())
          .exit_code,
      0);
  EXPECT_EQ(read_text(folder.path() / "cube.vtu"), read_text(folder.path() / "again.vtu"));
}

TEST(CliMesh, InfoOnASurfaceReportsClosedness) {
  TempFolder folder;
  write_text(folder.path() / "cube.off", kCubeOff);
  CliResult info = run_strata("info cube.off", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("triangles         12"));
  EXPECT_THAT(info.out, HasSubstr("closed            yes"));
  EXPECT_THAT(info.out, HasSubstr("enclosed volume   1\n"));
  std::string open = kCubeOff;  // drop the last quad
  open.replace(open.find("8 6 0"), 5, "8 5 0");
  open.erase(open.find("4 1 3 7 5"));
  write_text(folder.path() / "open.off", open);
  info = run_strata("info open.off", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("closed            no (4 boundary edges)"));
}

TEST(CliMesh, BadInputFailsWithOneLine) {
  TempFolder folder;
  write_text(folder.path() / "cube.off", kCubeOff);
  write_text(folder.path() / "empty.off", "OFF\n0 0 0\n");
  write_text(folder.path() / "points.xyz", "0 0 0\n");
  const struct {
    std::string arguments;
    std::string message;
  } cases[] = {
      {"mesh missing.off --cell-size 0.3 --out m.vtu", "missing.off: no such file"},
      {"mesh points.xyz --cell-size 0.3 --out m.vtu", "points.xyz: unknown surface format"},
      {"mesh empty.off --cell-size 0.3 --out m.vtu", "empty.off: the surface has no triangles"},
      {"mesh cube.off --cell-size 0.3 --out m.xyz", "m.xyz"},
      {"mesh cube.off --cell-size 0.0001 --out m.vtu",
       "cube.off: meshing: cell_size 0.0001 would give about 1e+13 tets"},
      {"mesh cube.off --cell-size 0.3 --facet-angle 45 --out m.vtu",
       "facet_angle must be in (0, 30] degrees"},
  };
  for (const auto& c : cases) {
    const CliResult result = run_strata(c.arguments, folder.path());
    EXPECT_EQ(result.exit_code, 2) << c.arguments;
    EXPECT_THAT(result.err, StartsWith("strata: error: ")) << c.arguments;
    EXPECT_THAT(result.err, HasSubstr(c.message)) << c.arguments;
    EXPECT_EQ(count_lines(result.err), 1) << c.arguments << ": " << result.err;
  }
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "m.vtu"));
}

/// A static scene on the meshed unit cube, fixed at z = 0, under gravity.
json cube_scene() {
  return json::parse(R"({
    "mesh": {"surface": "cube.off", "cell_size": 0.35, "sharp_features": true},
    "material": {"model": "neohookean", "youngs_modulus": 1e8, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [0, 0, 0], "max": [1, 1, 0]}}],
    "solver": {"mode": "static", "load_steps": 1, "newton_tolerance": 1e-8}
  })");
}

TEST(CliMesh, SceneWithSurfaceMeshesOnceThenUsesTheCache) {
  TempFolder folder;
  write_text(folder.path() / "cube.off", kCubeOff);
  write_text(folder.path() / "scene.json", cube_scene().dump(2));
  CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  json stats = read_json(folder.path() / "out" / "scene" / "stats.json");
  ASSERT_TRUE(stats.contains("meshing")) << stats.dump(2);
  EXPECT_EQ(stats["meshing"]["route"], "polyhedral");
  EXPECT_EQ(stats["meshing"]["from_cache"], false);
  EXPECT_EQ(stats["meshing"]["tets"], stats["tets"]);
  EXPECT_NEAR(stats["meshing"]["volume_ratio"].get<double>(), 1.0, 1e-12);
  EXPECT_GT(stats["meshing"]["min_dihedral_angle_deg"].get<double>(), 0.0);
  // The reaction carries the weight ρ V g of the meshed cube (V = 1 with sharp features).
  const Csv reactions = read_csv(folder.path() / "out" / "scene" / "reactions.csv");
  ASSERT_FALSE(reactions.rows.empty());
  EXPECT_NEAR(reactions.rows.back()[4], 1000.0 * 9.81, 1e-6 * 1000.0 * 9.81);

  result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json again = read_json(folder.path() / "out" / "scene" / "stats.json");
  EXPECT_EQ(again["meshing"]["from_cache"], true);
  EXPECT_EQ(again["tets"], stats["tets"]);
  EXPECT_EQ(again["max_displacement"], stats["max_displacement"]);

  const CliResult info = run_strata("info scene.json", folder.path());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("meshing           polyhedral, from the cache"));
}

TEST(CliMesh, SceneWithMissingSurfaceNamesTheKey) {
  TempFolder folder;
  json scene = cube_scene();
  scene["mesh"]["surface"] = "nothere.stl";
  write_text(folder.path() / "scene.json", scene.dump(2));
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("scene.json: mesh.surface: "));
  EXPECT_THAT(result.err,
              HasSubstr("scene.json: mesh.surface: cannot read 'nothere.stl': no such file"));
  EXPECT_EQ(count_lines(result.err), 1) << result.err;
}

}  // namespace
}  // namespace strata::cli_test
