// End to end: a scene with a fine surface writes <stem>_surface_NNNNNN.vtp beside every volume
// frame, listed in the .pvd as part 1, whose points follow the volume's displacement field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <map>
#include <regex>

#include "cli_test_utils.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "surface_test_utils.hpp"

namespace strata::cli_test {
namespace {

using ::testing::HasSubstr;

TEST(SurfaceFrames, FineSurfaceFollowsTheVolumeDisplacement) {
  TempFolder folder;
  MatrixX3d surface;
  write_text(folder.path() / "bar.off", bar_off(surface));
  write_text(folder.path() / "scene.json", R"({
    "mesh": {"surface": "bar.off", "cell_size": 0.06, "facet_distance": 0.005},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
    "solver": {"mode": "static", "load_steps": 2}
  })");
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  if (result.exit_code == 2 && result.err.find("not available") != std::string::npos)
    GTEST_SKIP() << "surface meshing not available yet: " << result.err;
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::filesystem::path out = folder.path() / "out" / "scene";

  // The .pvd lists volume (part 0) and surface (part 1) frames at the same times.
  const std::string pvd = read_text(out / "scene.pvd");
  for (const char* frame : {"000000", "000001", "000002"}) {
    EXPECT_THAT(pvd, HasSubstr("part=\"0\" file=\"scene_" + std::string(frame) + ".vtu\""));
    EXPECT_THAT(pvd, HasSubstr("part=\"1\" file=\"scene_surface_" + std::string(frame) + ".vtp\""));
  }

  // Frame 0 is the rest state: the surface is the input, to rounding of the extrapolation.
  const TetMesh rest = read_vtu(out / "scene_000000.vtu");
  const MatrixX3d surface0 = read_vtp_points(out / "scene_surface_000000.vtp");
  ASSERT_EQ(surface0.rows(), surface.rows());
  EXPECT_LT((surface0 - surface).cwiseAbs().maxCoeff(), 1e-12);

  // Last frame: inside vertices move with the barycentric interpolation of the volume frame,
  // computed here independently with the core's point locator.
  const TetMesh deformed = read_vtu(out / "scene_000002.vtu");
  // Inside vertices move with the barycentric interpolation of the volume frame.
  expect_surface_follows_volume(surface, read_vtp_points(out / "scene_surface_000002.vtp"), rest,
                                deformed);
}

TEST(SurfaceFrames, VtkSurfaceWritesOnlyTheSurfaceFrames) {
  // "vtk": "surface" keeps the fine surface's frames (the same points as with full output) and
  // writes no volume frames; any other string is an error naming the key.
  TempFolder folder;
  MatrixX3d surface;
  write_text(folder.path() / "bar.off", bar_off(surface));
  const std::string scene = R"({
    "mesh": {"surface": "bar.off", "cell_size": 0.06, "facet_distance": 0.005},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
    "solver": {"mode": "static", "load_steps": 2},
    "output": {"vtk": VTK}
  })";
  for (const char* vtk : {"true", "\"surface\""}) {
    write_text(folder.path() / (std::string(vtk) == "true" ? "all.json" : "surface.json"),
               std::regex_replace(scene, std::regex("VTK"), vtk));
  }
  for (const char* name : {"all", "surface"}) {
    const CliResult result =
        run_strata(std::string("run ") + name + ".json --quiet", folder.path());
    if (result.exit_code == 2 && result.err.find("not available") != std::string::npos)
      GTEST_SKIP() << "surface meshing not available yet: " << result.err;
    ASSERT_EQ(result.exit_code, 0) << result.err;
  }
  const std::filesystem::path all = folder.path() / "out" / "all";
  const std::filesystem::path only = folder.path() / "out" / "surface";
  EXPECT_TRUE(std::filesystem::exists(all / "all_000002.vtu"));
  EXPECT_FALSE(std::filesystem::exists(only / "surface_000000.vtu"));
  for (const char* frame : {"000000", "000002"}) {
    const MatrixX3d a = read_vtp_points(all / ("all_surface_" + std::string(frame) + ".vtp"));
    const MatrixX3d b = read_vtp_points(only / ("surface_surface_" + std::string(frame) + ".vtp"));
    ASSERT_EQ(a.rows(), surface.rows());
    EXPECT_EQ(a, b) << frame;
  }
  write_text(folder.path() / "bad.json", std::regex_replace(scene, std::regex("VTK"), "\"mesh\""));
  const CliResult bad = run_strata("run bad.json --quiet", folder.path());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("output.vtk"));
}

}  // namespace
}  // namespace strata::cli_test
