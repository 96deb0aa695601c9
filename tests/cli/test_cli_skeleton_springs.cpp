// Scenes with "body": {"model": "skeleton_springs"} end to end: a cantilever of springs on a bar
// surface and its skeleton, at rest under its tip load (the clamp's reaction balances the load),
// the outputs (probes, reactions, surface and skeleton frames, stats), and the errors for
// scenes the model does not support.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "cli_test_utils.hpp"
#include "surface_test_utils.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json cantilever() {
  return json::parse(R"({
    "mesh": {"surface": "bar.off"},
    "body": {"model": "skeleton_springs"},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1.0, "damping": {"mass": 6.0}},
    "fixed": [{"box": {"min": [-1, -1, -1], "max": [0.02, 1, 1]}}],
    "forces": [{"region": {"box": {"min": [1, -1, -1], "max": [2, 1, 1]}},
                "total_force": [0, 0, -0.05]}],
    "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.05, "duration": 10},
    "output": {"every": 20, "probes": [[1, 0.1, 0.1], [0.5, 0.1, 0.2]]}
  })");
}

TEST(CliSkeletonSprings, ACantileverComesToRestAndWritesItsOutputs) {
  const TempFolder folder;
  MatrixX3d vertices;
  write_text(folder.path() / "bar.off", bar_off(vertices));
  write_text(folder.path() / "beam.json", cantilever().dump(2));
  const CliResult result = run_strata("run beam.json", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("skeleton springs on bar.off"));
  const std::filesystem::path out = folder.path() / "out" / "beam";
  const json stats = read_json(out / "stats.json");
  EXPECT_EQ(stats["body"], "skeleton_springs");
  EXPECT_EQ(stats["skeleton"]["surface_vertices"], vertices.rows());
  EXPECT_GT(stats["skeleton"]["skeleton_points"].get<int>(), 5);
  EXPECT_NEAR(stats["skeleton"]["mass"].get<double>(), 1.0 * 0.04, 1e-12);
  // At rest, the clamp holds the load: R = −F.
  const Csv reactions = read_csv(out / "reactions.csv");
  ASSERT_FALSE(reactions.rows.empty());
  const std::vector<double>& last = reactions.rows.back();
  EXPECT_NEAR(last[2], 0.0, 1e-4);
  EXPECT_NEAR(last[4], 0.05, 0.05 * 0.01);
  // The tip (the probe at the end face's centre is a surface vertex) deflects as the stiffness
  // rule predicts, within its stated factor of 1.5 of Euler–Bernoulli, F L³ / (3 E I).
  const Csv probes = read_csv(out / "probes.csv");
  ASSERT_EQ(probes.rows.size(), 2u * 11u);  // frames at t = 0, 1, …, 10 s
  const double predicted = 0.05 / (3.0 * 1e6 * std::pow(0.2, 4) / 12.0);
  const double tip = -probes.rows[probes.rows.size() - 2][7];
  EXPECT_GT(tip, predicted / 1.5);
  EXPECT_LT(tip, predicted * 1.5);
  // Surface (part 0) and skeleton (part 1) frames.
  const std::string pvd = read_text(out / "beam.pvd");
  EXPECT_THAT(pvd, HasSubstr("beam_000010.vtp"));
  EXPECT_THAT(pvd, HasSubstr("beam_skeleton_000010.vtp"));
  const VtkFrame skeleton = read_vtk_frame(out / "beam_skeleton_000010.vtp");
  ASSERT_EQ(skeleton.cells.size(), 2u);
  EXPECT_EQ(skeleton.cells[0].first, "Lines/connectivity");
  EXPECT_EQ(read_vtp_points(out / "beam_000010.vtp").rows(), vertices.rows());
}

TEST(CliSkeletonSprings, ASimplifiedBodyCarriesTheFullSurface) {
  const TempFolder folder;
  MatrixX3d vertices;
  write_text(folder.path() / "bar.off", bar_off(vertices));
  ASSERT_GT(vertices.rows(), 300);
  json scene = cantilever();
  scene["body"]["surface_vertices"] = 200;
  write_text(folder.path() / "beam.json", scene.dump(2));
  const CliResult result = run_strata("run beam.json", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("(simplified from " + std::to_string(vertices.rows())));
  const std::filesystem::path out = folder.path() / "out" / "beam";
  const json stats = read_json(out / "stats.json");
  EXPECT_TRUE(stats["skeleton"]["simplified"].get<bool>());
  EXPECT_LE(stats["skeleton"]["surface_vertices"].get<int>(), 200);
  EXPECT_EQ(stats["skeleton"]["shown_surface_vertices"], vertices.rows());
  EXPECT_NEAR(stats["skeleton"]["mass"].get<double>(), 1.0 * 0.04, 1e-12);
  // The clamp holds the load at rest, and the tip probe (a vertex of the full surface, carried by
  // the simplified one) bends with the load. (Coarser springs are stiffer: the README gives the
  // measured deflections.)
  const std::vector<double>& last = read_csv(out / "reactions.csv").rows.back();
  EXPECT_NEAR(last[4], 0.05, 0.05 * 0.01);
  const Csv probes = read_csv(out / "probes.csv");
  EXPECT_LT(probes.rows[probes.rows.size() - 2][7], 0.0);
  // Part 0 is the full surface (its points the rest ones plus the displacement, the tip probe's
  // displacement that of its nearest vertex), part 2 the simulated one.
  const VtkFrame last_frame = read_vtk_frame(out / "beam_000010.vtp");
  ASSERT_EQ(last_frame.points.rows(), vertices.rows());
  const Eigen::MatrixXd& shown_displacement = last_frame.point_field("displacement");
  EXPECT_LT((last_frame.points - vertices - shown_displacement).cwiseAbs().maxCoeff(), 1e-12);
  Index tip = 0;
  (vertices.rowwise() - Eigen::RowVector3d(1, 0.1, 0.1)).rowwise().squaredNorm().minCoeff(&tip);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(probes.rows[probes.rows.size() - 2][5 + c], shown_displacement(tip, c), 1e-12);
  EXPECT_LE(read_vtp_points(out / "beam_springs_000010.vtp").rows(), 200);
  EXPECT_THAT(read_text(out / "beam.pvd"), HasSubstr("part=\"2\""));
  // Without simplification no springs part is written.
  scene["body"]["surface_vertices"] = 0;
  write_text(folder.path() / "whole.json", scene.dump(2));
  ASSERT_EQ(run_strata("run whole.json -q", folder.path()).exit_code, 0);
  const json whole = read_json(folder.path() / "out" / "whole" / "stats.json");
  EXPECT_FALSE(whole["skeleton"]["simplified"].get<bool>());
  EXPECT_EQ(whole["skeleton"]["surface_vertices"], vertices.rows());
  EXPECT_FALSE(
      std::filesystem::exists(folder.path() / "out" / "whole" / "whole_springs_000000.vtp"));
}

TEST(CliSkeletonSprings, UnsupportedScenesGetOneLineErrors) {
  const TempFolder folder;
  MatrixX3d vertices;
  std::string off = bar_off(vertices);
  write_text(folder.path() / "bar.off", off);
  // An open surface: the last triangle dropped.
  off = off.substr(0, off.rfind("3 ", off.size() - 2));
  const std::size_t header = off.find('\n') + 1;
  const std::string counts = off.substr(header, off.find('\n', header) - header);
  const long faces = std::stol(counts.substr(counts.find(' ') + 1));
  off.replace(header, counts.size(),
              std::to_string(vertices.rows()) + " " + std::to_string(faces - 1) + " 0");
  write_text(folder.path() / "open.off", off);
  const auto error = [&](const json& scene) {
    write_text(folder.path() / "bad.json", scene.dump(2));
    const CliResult result = run_strata("run bad.json -q", folder.path());
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    return result.err;
  };
  json scene = cantilever();
  scene["mesh"] = {{"box", {{"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"cells", {1, 1, 1}}}}};
  EXPECT_THAT(error(scene), HasSubstr("body.model: skeleton_springs needs mesh.surface"));
  scene = cantilever();
  scene["hierarchy"] = {{"levels", 1}};
  EXPECT_THAT(error(scene), HasSubstr("hierarchy: not supported with body.model"));
  scene = cantilever();
  scene["solver"] = {{"mode", "static"}};
  EXPECT_THAT(error(scene), HasSubstr("runs dynamic only"));
  scene = cantilever();
  scene["body"] = {{"model", "tets"}, {"tie_scale", 2}};
  EXPECT_THAT(error(scene), HasSubstr("body.tie_scale: only with model \"skeleton_springs\""));
  scene = cantilever();
  scene["body"] = {{"model", "tets"}, {"surface_vertices", 100}};
  EXPECT_THAT(error(scene),
              HasSubstr("body.surface_vertices: only with model \"skeleton_springs\""));
  scene = cantilever();
  scene["body"]["surface_vertices"] = 3;
  EXPECT_THAT(error(scene), HasSubstr("body.surface_vertices: expected 0"));
  scene = cantilever();
  scene["body"]["shell_ratio"] = -1;
  EXPECT_THAT(error(scene), HasSubstr("body.shell_ratio"));
  scene = cantilever();
  scene["mesh"]["cell_size"] = 0.1;
  EXPECT_THAT(error(scene), HasSubstr("mesh.cell_size"));
  scene = cantilever();
  scene["mesh"]["surface"] = "open.off";
  EXPECT_THAT(error(scene), HasSubstr("mesh.surface: the surface has holes"));
  scene["body"]["surface_vertices"] = 100;  // the simplification finds the holes first
  EXPECT_THAT(error(scene), HasSubstr("bad.json: mesh.surface: the surface has holes"));
  scene = cantilever();
  scene["output"]["probes"] = {{5, 5, 5}};
  EXPECT_THAT(error(scene), HasSubstr("output.probes.0"));
}

}  // namespace
}  // namespace strata::cli_test
