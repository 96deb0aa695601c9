// End-to-end runs of the strata executable on tiny scenes: exit codes, output files and their
// content against independent computations (weight, applied load, discrete free fall).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include <gnu/libc-version.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_utils.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/stable_time_step.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

/// A 1 × 0.1 × 0.1 m bar of 10 × 1 × 1 cells (44 vertices, 60 tets) fixed at x = 0.
json bar_scene() {
  return json::parse(R"({
    "mesh": {"box": {"min": [0, 0, 0], "max": [1, 0.1, 0.1], "cells": [10, 1, 1]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e9, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [0, 0, 0], "max": [0, 0.1, 0.1]}}],
    "solver": {"mode": "static", "load_steps": 2, "newton_tolerance": 1e-8},
    "output": {"probes": [[0, 0, 0], [1, 0.05, 0.05]]}
  })");
}

std::filesystem::path write_scene(const TempFolder& folder, const json& scene,
                                  const std::string& name = "scene.json") {
  const std::filesystem::path path = folder.path() / name;
  write_text(path, scene.dump(2));
  return path;
}

TEST(CliEndToEnd, ProgressFileEndsAtTheWholeRun) {
  TempFolder folder;
  write_scene(folder, bar_scene());
  const CliResult result =
      run_strata("run scene.json --quiet --progress-file progress.txt", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "progress.txt.part"));
  std::istringstream line(read_text(folder.path() / "progress.txt"));
  double fraction = -1.0;
  double elapsed = -1.0;
  ASSERT_TRUE(line >> fraction >> elapsed) << read_text(folder.path() / "progress.txt");
  EXPECT_EQ(fraction, 1.0);  // written at the last step, whatever the throttle
  EXPECT_GE(elapsed, 0.0);
  const json stats = read_json(folder.path() / "out" / "scene" / "stats.json");
  EXPECT_LE(elapsed, stats["wall_seconds"].get<double>() + 1e-3);
}

/// The kernel's THP mode (the bracketed word of its sysfs file), "" without one.
std::string thp_mode() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  std::getline(file, line);
  const auto open = line.find('[');
  const auto close = line.find(']');
  return open == std::string::npos || close == std::string::npos
             ? ""
             : line.substr(open + 1, close - open - 1);
}

/// Runs scene.json in `folder` with `name`=`value` set in the environment (unset when value is
/// null) and returns stats.json's huge_pages and the probes.
std::pair<std::string, std::string> run_with_environment(const TempFolder& folder, const char* name,
                                                         const char* value) {
  const char* before = std::getenv(name);
  const std::string saved = before != nullptr ? before : "";
  if (value != nullptr)
    setenv(name, value, 1);
  else
    unsetenv(name);
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  if (before != nullptr)
    setenv(name, saved.c_str(), 1);
  else
    unsetenv(name);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, "");
  EXPECT_EQ(result.err, "");
  const std::filesystem::path out = folder.path() / "out" / "scene";
  return {read_json(out / "stats.json")["huge_pages"].get<std::string>(),
          read_text(out / "probes.csv")};
}

TEST(CliEndToEnd, HugePageHeapFollowsTheKernelAndTheOptOuts) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr &&
      std::string(tunables).find("glibc.malloc.hugetlb") != std::string::npos)
    GTEST_SKIP() << "GLIBC_TUNABLES of the test names glibc.malloc.hugetlb";
  TempFolder folder;
  write_scene(folder, bar_scene());
  const std::string mode = thp_mode();
  int major = 0, minor = 0;
  std::sscanf(gnu_get_libc_version(), "%d.%d", &major, &minor);
  const bool tunable_known = major > 2 || (major == 2 && minor >= 35);
  const std::string off = mode == "always" ? "always (kernel)" : "off";
  const std::string expected = mode == "madvise" && tunable_known ? "on" : off;

  const auto [state, probes] = run_with_environment(folder, "STRATA_HUGE_PAGES", nullptr);
  EXPECT_EQ(state, expected) << "THP mode " << mode;
  const auto [opted_out, opted_out_probes] = run_with_environment(folder, "STRATA_HUGE_PAGES", "0");
  EXPECT_EQ(opted_out, off);
  EXPECT_EQ(opted_out_probes, probes);  // the heap's pages do not change a result
  const auto [tuned, tuned_probes] =
      run_with_environment(folder, "GLIBC_TUNABLES", "glibc.malloc.hugetlb=0");
  EXPECT_EQ(tuned, off);  // a tunable already set is the user's
  EXPECT_EQ(tuned_probes, probes);
  // Other tunables stay, and the huge-page one is added after them.
  const auto [other, other_probes] =
      run_with_environment(folder, "GLIBC_TUNABLES", "glibc.malloc.trim_threshold=4294967296");
  EXPECT_EQ(other, expected);
  EXPECT_EQ(other_probes, probes);
  if (expected != "on")
    std::cout << "[ NOTE     ] THP mode '" << mode << "', glibc " << gnu_get_libc_version()
              << ": the re-execution is not exercised on this machine\n";
}

TEST(CliEndToEnd, StaticGravityReactionEqualsWeight) {
  TempFolder folder;
  write_scene(folder, bar_scene());
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::filesystem::path out = folder.path() / "out" / "scene";

  const Csv reactions = read_csv(out / "reactions.csv");
  EXPECT_EQ(reactions.header, "time,group,fx,fy,fz,mx,my,mz");
  ASSERT_EQ(reactions.rows.size(), 3u);  // load factors 0, 0.5, 1; one group
  const std::vector<double>& last = reactions.rows.back();
  EXPECT_DOUBLE_EQ(last[0], 1.0);
  EXPECT_EQ(last[1], 0.0);
  const double weight = 1000.0 * 0.01 * 9.81;  // ρ V g [N]
  EXPECT_NEAR(last[2], 0.0, 1e-6 * weight);
  EXPECT_NEAR(last[3], 0.0, 1e-6 * weight);
  EXPECT_NEAR(last[4], weight, 1e-6 * weight);
  // Moment about the fixed face's centroid (0, 0.05, 0.05): the weight acts at x ≈ 0.5 m, so
  // the support holds M_y = −0.5 W (deflection shifts the lever by ~δ²/L, negligible here).
  // Lever arms change by at most the largest displacement, which bounds the other components.
  const json stats = read_json(out / "stats.json");
  const double max_displacement = stats["max_displacement"].get<double>();
  EXPECT_GT(max_displacement, 0.0);
  EXPECT_NEAR(last[6], -0.5 * weight, max_displacement * weight);
  EXPECT_NEAR(last[5], 0.0, max_displacement * weight);
  EXPECT_NEAR(last[7], 0.0, max_displacement * weight);
  // Half the load at load factor 0.5; nothing at 0.
  EXPECT_NEAR(reactions.rows[1][4], 0.5 * weight, 1e-6 * weight);
  EXPECT_NEAR(reactions.rows[0][4], 0.0, 1e-9 * weight);

  const Csv probes = read_csv(out / "probes.csv");
  EXPECT_EQ(probes.header, "time,probe,x,y,z,ux,uy,uz");
  ASSERT_EQ(probes.rows.size(), 6u);  // 3 frames × 2 probes
  for (const std::vector<double>& row : probes.rows) {
    ASSERT_EQ(row.size(), 8u);
    if (row[1] == 0.0) {  // a fixed vertex
      EXPECT_EQ(row[5], 0.0);
      EXPECT_EQ(row[6], 0.0);
      EXPECT_EQ(row[7], 0.0);
    }
  }
  EXPECT_EQ(probes.rows[5][1], 1.0);
  EXPECT_DOUBLE_EQ(probes.rows[5][2], 1.0);
  // Tip deflection: downwards, below Euler–Bernoulli's qL⁴/(8EI) (tets are stiffer), and almost
  // linear in the load at this tiny strain.
  const double beam_theory = weight * 1.0 / (8.0 * 1e9 * std::pow(0.1, 4) / 12.0);
  const double tip = probes.rows[5][7];
  EXPECT_LT(tip, 0.0);
  EXPECT_GT(tip, -1.1 * beam_theory);
  EXPECT_NEAR(probes.rows[3][7], 0.5 * tip, 1e-3 * std::abs(tip));

  EXPECT_EQ(stats["status"], "ok");
  EXPECT_EQ(stats["steps"], 2);
  EXPECT_EQ(stats["vertices"], 44);
  EXPECT_EQ(stats["tets"], 60);
  EXPECT_EQ(stats["dofs"], 132);
  EXPECT_EQ(stats["reoriented_tets"], 0);
  for (const char* key : {"wall_seconds", "newton_iterations", "element_evaluations",
                          "stable_dt_estimate", "material", "energies"}) {
    EXPECT_TRUE(stats.contains(key)) << key;
  }
  EXPECT_GT(stats["newton_iterations"].get<long>(), 0);
  EXPECT_GT(stats["element_evaluations"].get<long long>(), 0);

  EXPECT_TRUE(std::filesystem::exists(out / "scene.pvd"));
  EXPECT_TRUE(std::filesystem::exists(out / "scene_000000.vtu"));
  EXPECT_TRUE(std::filesystem::exists(out / "scene_000002.vtu"));
  const std::string vtu = read_text(out / "scene_000002.vtu");
  for (const char* field :
       {"displacement", "velocity", "green_strain", "stress", "von_mises", "level"}) {
    EXPECT_THAT(vtu, HasSubstr(std::string("Name=\"") + field + "\"")) << field;
  }
}

TEST(CliEndToEnd, TipForceReactionAndOverrides) {
  TempFolder folder;
  json scene = bar_scene();
  scene.erase("gravity");
  scene["forces"] = json::parse(
      R"([{"region": {"box": {"min": [1, 0, 0], "max": [1, 0.1, 0.1]}}, "total_force": [0, 0, 1]}])");
  scene["output"]["vtk"] = false;
  write_scene(folder, scene);
  const CliResult result = run_strata(
      "run scene.json --out results --quiet --set forces.0.total_force=[0,0,-100] "
      "--set solver.load_steps=1 --set output.probes.1.2=0.1",
      folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::filesystem::path out = folder.path() / "results";
  const Csv reactions = read_csv(out / "reactions.csv");
  ASSERT_EQ(reactions.rows.size(), 2u);
  EXPECT_NEAR(reactions.rows[1][4], 100.0, 1e-6 * 100.0);
  // Moment of the tip load about (0, 0.05, 0.05), lever (1 + u_x, 0, 0.05 + u_z) deformed.
  EXPECT_NEAR(reactions.rows[1][6], -100.0, 1e-2);
  const Csv probes = read_csv(out / "probes.csv");
  EXPECT_DOUBLE_EQ(probes.rows.back()[4], 0.1);  // the overridden probe z
  EXPECT_EQ(read_json(out / "stats.json")["steps"], 1);
  EXPECT_FALSE(std::filesystem::exists(out / "scene.pvd"));
}

TEST(CliEndToEnd, PrescribedStretchReactionsBalance) {
  TempFolder folder;
  json scene = bar_scene();
  scene.erase("gravity");
  scene["prescribed"] = json::parse(
      R"([{"region": {"plane": {"point": [1, 0, 0], "normal": [1, 0, 0]}},
           "displacement": [0.001, 0, 0]}])");
  scene["output"] = {{"vtk", false}};
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv reactions = read_csv(folder.path() / "out" / "scene" / "reactions.csv");
  ASSERT_EQ(reactions.rows.size(), 6u);  // 3 frames × (fixed.0, prescribed.0)
  const std::vector<double>& fixed = reactions.rows[4];
  const std::vector<double>& pulled = reactions.rows[5];
  EXPECT_EQ(fixed[1], 0.0);
  EXPECT_EQ(pulled[1], 1.0);
  // No body force: the two supports' forces cancel. Pulling needs a force of the order of
  // E A ε = 1e9 · 0.01 · 1e-3 = 1e4 N (more with the lateral constraint of the clamped ends).
  EXPECT_NEAR(fixed[2] + pulled[2], 0.0, 1e-6 * std::abs(pulled[2]));
  EXPECT_GT(pulled[2], 1e4);
  EXPECT_LT(pulled[2], 2e4);
}

TEST(CliEndToEnd, TwistReactionMomentsBalance) {
  TempFolder folder;
  json scene = bar_scene();
  scene.erase("gravity");
  scene["mesh"]["box"]["cells"] = {4, 2, 2};
  scene["material"]["youngs_modulus"] = 1e6;
  scene["prescribed"] = json::parse(
      R"([{"region": {"plane": {"point": [1, 0, 0], "normal": [1, 0, 0]}},
           "rotation": {"axis": [1, 0, 0], "center": [1, 0.05, 0.05], "angle_degrees": 30}}])");
  scene["solver"]["load_steps"] = 3;
  scene["output"] = json::parse(R"({"vtk": false, "probes": [[1, 0.1, 0.1]]})");
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv reactions = read_csv(folder.path() / "out" / "scene" / "reactions.csv");
  ASSERT_EQ(reactions.rows.size(), 8u);  // 4 frames × 2 groups
  const std::vector<double>& fixed = reactions.rows[6];
  const std::vector<double>& twisted = reactions.rows[7];
  // Both moment centers lie on the line y = z = 0.05, so the axial moments cancel exactly
  // (the lever between the centers is parallel to x); forces cancel without body forces.
  EXPECT_GT(twisted[5], 0.0);
  EXPECT_NEAR(fixed[5] + twisted[5], 0.0, 1e-6 * twisted[5]);
  for (int a = 2; a < 5; ++a) {
    EXPECT_NEAR(fixed[a] + twisted[a], 0.0, 1e-6 * twisted[5] / 0.1) << a;
  }
  // The probe at the rotated corner (1, 0.1, 0.1) follows the rotation by 30° about the x axis.
  const Csv probes = read_csv(folder.path() / "out" / "scene" / "probes.csv");
  const std::vector<double>& corner = probes.rows.back();
  const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
  EXPECT_NEAR(corner[5], 0.0, 1e-12);
  EXPECT_NEAR(corner[6], 0.05 * c - 0.05 * s - 0.05, 1e-12);
  EXPECT_NEAR(corner[7], 0.05 * s + 0.05 * c - 0.05, 1e-12);
}

/// Free fall without supports: elastic forces stay zero, so every scheme reproduces its own
/// discrete kinematics exactly.
TEST(CliEndToEnd, DynamicFreeFallMatchesDiscreteKinematics) {
  TempFolder folder;
  json scene = bar_scene();
  scene.erase("fixed");
  // Soft enough that dt = 0.01 s is below the explicit stability limit (round-off stays small).
  scene["material"]["youngs_modulus"] = 1e3;
  scene["solver"] = json::parse(R"({"mode": "dynamic", "dt": 0.01, "duration": 0.1})");
  scene["output"] = json::parse(R"({"every": 5, "probes": [[0.5, 0.05, 0.05]], "vtk": false})");
  const double g = 9.81, h = 0.01;
  const int n = 10;
  for (const auto& [integrator, expected] :
       {std::pair<std::string, double>{"implicit_euler", -g * h * h * n * (n + 1) / 2.0},
        {"symplectic_euler", -g * h * h * n * (n + 1) / 2.0},
        {"rk4", -0.5 * g * (n * h) * (n * h)}}) {
    scene["solver"]["integrator"] = integrator;
    write_scene(folder, scene);
    const CliResult result = run_strata("run scene.json --quiet", folder.path());
    ASSERT_EQ(result.exit_code, 0) << integrator << ": " << result.err;
    const Csv probes = read_csv(folder.path() / "out" / "scene" / "probes.csv");
    ASSERT_EQ(probes.rows.size(), 3u) << integrator;  // t = 0, 0.05, 0.1
    EXPECT_NEAR(probes.rows[2][0], 0.1, 1e-12);
    EXPECT_NEAR(probes.rows[2][7], expected, 1e-9) << integrator;
    EXPECT_NEAR(probes.rows[2][5], 0.0, 1e-12) << integrator;
    const json stats = read_json(folder.path() / "out" / "scene" / "stats.json");
    EXPECT_EQ(stats["steps"], n);
    EXPECT_EQ(stats["integrator"], integrator);
  }
}

TEST(CliEndToEnd, AnInterruptedRunLeavesNoStatsFile) {
  // A previous run's stats.json in the output folder; a long run into the same folder is
  // stopped with SIGTERM: the folder must not keep a stats.json that claims a finished run.
  TempFolder folder;
  json scene = bar_scene();
  scene["solver"] = json::parse(R"({"mode": "dynamic", "integrator": "implicit_euler", "dt": 1e-4,
                      "duration": 1000})");
  write_scene(folder, scene);
  const std::filesystem::path out = folder.path() / "out" / "scene";
  std::filesystem::create_directories(out);
  write_text(out / "stats.json", "{\"status\": \"ok\"}");
  const std::string command = "cd '" + folder.path().string() + "' && timeout -s TERM 5 '" +
                              STRATA_CLI_PATH + "' run scene.json -q > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 124);                       // stopped by the timeout, not finished
  EXPECT_TRUE(std::filesystem::exists(out / "probes.csv"));  // the run had started its outputs
  EXPECT_FALSE(std::filesystem::exists(out / "stats.json"));
}

TEST(CliEndToEnd, ExplicitBoxRunsBoundTheStableStepOverEachCell) {
  // A box mesh's explicit run bounds the stable step over each cell's six tets
  // (stable_time_step.hpp); an implicit run reports the single-tet bound, as a reference.
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.1, 0.1), {10, 1, 1});
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 1e9;
  material.poisson_ratio = 0.3;
  material.density = 1000;
  std::vector<int> cells(mesh.tets.rows());
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    cells[t] = static_cast<int>(t / 6);
  const double element =
      stable_time_step_estimate(mesh.vertices, mesh.tets, material, Integrator::symplectic_euler);
  const double grouped = stable_time_step_estimate(mesh.vertices, mesh.tets, material,
                                                   Integrator::symplectic_euler, cells);
  EXPECT_GT(grouped, 1.2 * element);
  for (const std::string integrator : {"symplectic_euler", "implicit_euler"}) {
    TempFolder folder;
    json scene = bar_scene();
    scene["solver"] = {{"mode", "dynamic"},
                       {"integrator", integrator},
                       {"dt", 0.5 * element},
                       {"duration", 5 * 0.5 * element}};
    write_scene(folder, scene);
    const CliResult result = run_strata("run scene.json -q", folder.path());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const json stats = read_json(folder.path() / "out" / "scene" / "stats.json");
    const double expected = integrator == "symplectic_euler" ? grouped : element;
    EXPECT_NEAR(stats["stable_dt_estimate"].get<double>(), expected, 1e-12 * expected)
        << integrator;
  }
}

TEST(CliEndToEnd, ExplicitRunBeyondStableStepDivergesWithExitCode3) {
  TempFolder folder;
  json scene = bar_scene();
  scene["material"]["youngs_modulus"] = 1e7;
  scene["solver"] =
      json::parse(R"({"mode": "dynamic", "integrator": "rk4", "dt": 0.01, "duration": 10})");
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json", folder.path());
  EXPECT_EQ(result.exit_code, 3) << result.err;
  EXPECT_THAT(result.err, HasSubstr("strata: warning: dt = 0.01 s exceeds the stable estimate"));
  EXPECT_THAT(result.err, HasSubstr("strata: error: "));
  EXPECT_THAT(result.out, HasSubstr("stable dt estimate"));
  const std::filesystem::path out = folder.path() / "out" / "scene";
  const json stats = read_json(out / "stats.json");
  EXPECT_EQ(stats["status"], "diverged");
  EXPECT_FALSE(stats["message"].get<std::string>().empty());
  EXPECT_LT(stats["steps"].get<long>(), 1000);
  EXPECT_GT(stats["dt"].get<double>(), stats["stable_dt_estimate"].get<double>());
  const Csv probes = read_csv(out / "probes.csv");
  EXPECT_EQ(probes.header, "time,probe,x,y,z,ux,uy,uz");
  EXPECT_GE(probes.rows.size(), 2u);  // at least the t = 0 frame
  EXPECT_EQ(read_csv(out / "reactions.csv").header, "time,group,fx,fy,fz,mx,my,mz");
  EXPECT_TRUE(std::filesystem::exists(out / "scene.pvd"));
  EXPECT_TRUE(std::filesystem::exists(out / "scene_000000.vtu"));
}

TEST(CliEndToEnd, BadInputExitsWith2AndOneLineErrors) {
  TempFolder folder;
  json scene = bar_scene();
  scene["output"]["probs"] = json::array();
  write_scene(folder, scene, "typo.json");
  CliResult result = run_strata("run typo.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(result.err, "strata: error: typo.json: output.probs: unknown key\n");

  result = run_strata("run missing.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, StartsWith("strata: error: missing.json"));

  write_text(folder.path() / "broken.json", "{\"mesh\": [1, 2,\n}");
  result = run_strata("run broken.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("broken.json: line 2, column 1"));

  write_scene(folder, bar_scene());
  result = run_strata("run scene.json --set material.youngs=3", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("--set material.youngs"));

  result = run_strata("run scene.json --set output.probes.0=[5,5,5]", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("output.probes.0: point (5, 5, 5) lies outside the mesh"));

  result = run_strata("run scene.json --set fixed.0.box.min=[3,3,3] --set fixed.0.box.max=[4,4,4]",
                      folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("fixed.0"));

  result = run_strata("run", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  result = run_strata("frobnicate", folder.path());
  EXPECT_EQ(result.exit_code, 2);
}

/// Writes `scene` as scene.json, runs it and expects exit 2 with one line on stderr holding
/// `message`.
void expect_refused(const TempFolder& folder, const json& scene, const std::string& message) {
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json", folder.path());
  EXPECT_EQ(result.exit_code, 2) << message;
  EXPECT_THAT(result.err, HasSubstr(message));
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST(CliEndToEnd, StepCountsFollowTheDocumentedRuleAndItsLimits) {
  TempFolder folder;
  json scene = bar_scene();
  // A duration below dt takes one step (⌈duration / dt⌉, at least one).
  scene["solver"] = json::parse(
      R"({"mode": "dynamic", "integrator": "implicit_euler", "dt": 1, "duration": 1e-9})");
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_json(folder.path() / "out" / "scene" / "stats.json")["steps"], 1);
  // Runs that would not end are refused at once.
  scene["solver"]["dt"] = 1e-12;
  scene["solver"]["duration"] = 1;
  expect_refused(folder, scene,
                 "strata: error: scene.json: solver.dt: duration / dt = 1e+12 steps (at most 1e8)");
  scene["solver"] = json::parse(R"({"mode": "static", "load_steps": 1000000000})");
  expect_refused(folder, scene, "scene.json: solver.load_steps: must be at most 1e6");
}

TEST(CliEndToEnd, OverflowsHugeMeshesAndControlCharactersGiveOneLineBadInputErrors) {
  TempFolder folder;
  // A literal beyond a double.
  write_text(folder.path() / "huge.json",
             "{\"mesh\": {\"box\": {\"min\": [0, 0, 0], "
             "\"max\": [1e400, 1, 1], \"cells\": [1, 1, 1]}}}");
  const CliResult result = run_strata("run huge.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(result.err,
            "strata: error: huge.json: line 1, column 45: number overflow parsing '1e400' (not a "
            "finite double)\n");
  // Found as a number, not in a string or inside another number before it.
  write_text(folder.path() / "later.json",
             "{\"name\": \"1e309\", \"x\": 0.001e309,\n  \"mesh\": [\n    1e309]}");
  EXPECT_EQ(run_strata("run later.json", folder.path()).err,
            "strata: error: later.json: line 3, column 5: number overflow parsing '1e309' (not a "
            "finite double)\n");
  // Finite values whose products overflow: the weight, or the stiffness.
  json scene = bar_scene();
  scene["gravity"] = {0, 0, -1e300};
  expect_refused(folder, scene, "scene.json: loads: the masses or the loads");
  scene = bar_scene();
  scene["material"]["youngs_modulus"] = 1e300;
  expect_refused(folder, scene, "scene.json: material.youngs_modulus: must be at most 1e20");
  // A mesh the machine cannot hold is refused before it is built, naming the key.
  scene = bar_scene();
  scene["mesh"]["box"]["cells"] = {2000, 2000, 2000};
  expect_refused(folder, scene, "scene.json: mesh.box: cells: about 4.8e+10 tets would need");
  scene = bar_scene();
  scene["hierarchy"] = {{"levels", 8}, {"mode", "full"}};
  expect_refused(folder, scene, "scene.json: hierarchy.levels: about");
  // A newline inside a value the message quotes stays on the one line, escaped.
  scene = bar_scene();
  scene["material"]["model"] = "stvk\nstrata: error: a second line";
  expect_refused(folder, scene, "\"stvk\\nstrata: error: a second line\"");
}

/// Runs `arguments` in `folder` and expects exit 2 with exactly the one line `line` on stderr.
void expect_error_line(const TempFolder& folder, const std::string& arguments,
                       const std::string& line) {
  const CliResult result = run_strata(arguments, folder.path());
  EXPECT_EQ(result.exit_code, 2) << arguments;
  EXPECT_EQ(result.err, "strata: error: " + line + "\n") << arguments;
}

TEST(CliEndToEnd, DuplicateKeysFoldersAndFilesAreNamedInTheError) {
  TempFolder folder;
  // nlohmann's parser keeps the last of two equal keys; the scene reader refuses them.
  write_text(folder.path() / "twice.json", R"({"mesh": {"box": {"cells": [1, 1, 1],
      "min": [0, 0, 0], "max": [1, 1, 1]}}, "fixed": [{"box": {"min": [0, 0, 0],
      "max": [0, 1, 1], "min": [1, 1, 1]}}]})");
  expect_error_line(folder, "run twice.json",
                    "twice.json: fixed.0.box.min: duplicate key (each key may appear once in an "
                    "object)");
  std::filesystem::create_directories(folder.path() / "folder.json");
  expect_error_line(folder, "run folder.json", "folder.json: is a folder, not a JSON file");
  // Files named by the scene are checked when it is read, under their key.
  json scene = bar_scene();
  scene["obstacles"] = json::array({{{"surface", "nothere.off"}}});
  expect_refused(folder, scene,
                 "scene.json: obstacles.0.surface: cannot read 'nothere.off': no such file");
  scene = bar_scene();
  scene["mesh"] = {{"file", "folder.json"}};
  expect_refused(folder, scene, "scene.json: mesh.file: cannot read 'folder.json': it is a folder");
  // "surface" frames need a fine surface.
  scene = bar_scene();
  scene["output"]["vtk"] = "surface";
  expect_refused(folder, scene, "scene.json: output.vtk: \"surface\" writes the fine surface");
  // Integers beyond an int say so.
  scene = bar_scene();
  scene["mesh"]["box"]["cells"][0] = 3e9;
  expect_refused(folder, scene,
                 "scene.json: mesh.box.cells.0: must be an integer of at most 2147483647");
}

TEST(CliEndToEnd, KeysTheRunDoesNotUseAreWarnedAbout) {
  TempFolder folder;
  // The run's stderr: warnings only, and a run that exits 0.
  const auto warnings = [&](const json& scene) {
    write_scene(folder, scene);
    const CliResult result = run_strata("run scene.json -q", folder.path());
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return result.err;
  };
  json scene = bar_scene();  // static
  scene["solver"]["dt"] = 0.01;
  EXPECT_EQ(warnings(scene),
            "strata: warning: scene.json: solver.dt: applies to dynamic runs only (ignored)\n");
  scene = bar_scene();  // static: the obstacles stand where they are at t = 0
  scene["obstacles"] = json::parse(
      R"([{"plane": {"point": [0, 0, -10], "normal": [0, 0, 1]}},
          {"plane": {"point": [0, 0, -20], "normal": [0, 0, 1]}, "motion": {"velocity": [0, 0, 1]}}])");
  EXPECT_EQ(warnings(scene),
            "strata: warning: scene.json: obstacles.1.motion: applies to dynamic runs only "
            "(ignored)\n");
  scene = bar_scene();
  scene["solver"] =
      json::parse(R"({"mode": "dynamic", "dt": 0.01, "duration": 0.01, "load_steps": 4})");
  scene["hierarchy"] = {{"levels", 1}, {"mode", "full"}, {"level", 0}};
  EXPECT_EQ(warnings(scene),
            "strata: warning: scene.json: solver.load_steps: applies to static runs only "
            "(ignored)\nstrata: warning: scene.json: hierarchy.level: mode \"full\" runs on the "
            "finest level (ignored)\n");
  // The keys of adaptation, in a mode that does not adapt.
  scene["solver"].erase("load_steps");
  scene["hierarchy"] = {
      {"levels", 1}, {"mode", "full"}, {"tolerance", 0.05}, {"max_active_elements", 100}};
  EXPECT_EQ(warnings(scene),
            "strata: warning: scene.json: hierarchy.max_active_elements: mode \"full\" does not "
            "adapt (ignored)\nstrata: warning: scene.json: hierarchy.tolerance: mode \"full\" does "
            "not adapt (ignored)\n");
  // A duration shorter than one step.
  scene.erase("hierarchy");
  scene["solver"] = json::parse(R"({"mode": "dynamic", "dt": 0.01, "duration": 0.004})");
  EXPECT_EQ(
      warnings(scene),
      "strata: warning: scene.json: solver.duration: 0.004 s is shorter than solver.dt 0.01 s "
      "(the run takes one step of dt)\n");
}

TEST(CliEndToEnd, OutputFolderAndProgressFileProblemsAreBadInput) {
  TempFolder folder;
  write_scene(folder, bar_scene());
  write_text(folder.path() / "afile", "x");
  expect_error_line(folder, "run scene.json --out afile/sub",
                    "output folder 'afile/sub': 'afile' is a file, not a folder");
  expect_error_line(folder, "run scene.json --out afile",
                    "output folder 'afile': 'afile' is a file, not a folder");
  expect_error_line(folder, "run scene.json --out ''",
                    "--out: the output folder must not be empty");
  expect_error_line(folder, "run scene.json --out o --progress-file nodir/p.txt",
                    "--progress-file 'nodir/p.txt': cannot write it (no folder 'nodir')");
  // The run failed before writing anything: the folder it created is gone again.
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "o"));
  std::filesystem::create_directories(folder.path() / "p");
  expect_error_line(folder, "run scene.json --out p --progress-file p",
                    "--progress-file 'p': cannot write it (it is a folder)");
  EXPECT_TRUE(std::filesystem::exists(folder.path() / "p"));  // not created by the run
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "p" / "stats.json"));
  expect_error_line(folder, "run scene.json --threads abc",
                    "--threads: expected a whole number, got 'abc'");
  expect_error_line(folder, "run scene.json --threads -1",
                    "--threads: must be between 0 and 4096, got -1");
}

TEST(CliEndToEnd, ASecondRunIntoTheSameFolderIsRefusedWhileTheFirstWrites) {
  TempFolder folder;
  json scene = bar_scene();
  scene["solver"] = json::parse(
      R"({"mode": "dynamic", "integrator": "implicit_euler", "dt": 1e-3, "duration": 10000})");
  scene["output"]["vtk"] = false;
  write_scene(folder, scene, "long.json");
  write_scene(folder, bar_scene());
  // The long run holds out/ until it is killed; the progress file says when it has started.
  const std::string command = "cd '" + folder.path().string() + "' && exec '" + STRATA_CLI_PATH +
                              "' run long.json --out out -q --progress-file progress.txt";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int i = 0; i < 600 && !std::filesystem::exists(folder.path() / "progress.txt"); ++i)
    usleep(50000);
  const bool started = std::filesystem::exists(folder.path() / "progress.txt");
  const CliResult second = run_strata("run scene.json --out out -q", folder.path());
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(started);
  EXPECT_EQ(second.exit_code, 2);
  EXPECT_EQ(second.err,
            "strata: error: output folder 'out': another strata run is writing to it (give each "
            "run its own --out)\n");
  // Once the first run is gone the folder is free again.
  const CliResult third = run_strata("run scene.json --out out -q", folder.path());
  EXPECT_EQ(third.exit_code, 0) << third.err;
}

TEST(CliEndToEnd, AStaticBodyItsConstraintsDoNotHoldIsToldWhy) {
  TempFolder folder;
  json scene = bar_scene();
  // One fixed corner vertex: the bar can still turn about it.
  scene["fixed"] = json::array({{{"sphere", {{"center", {0, 0, 0}}, {"radius", 1e-3}}}}});
  write_scene(folder, scene);
  const CliResult result = run_strata("run scene.json -q", folder.path());
  EXPECT_EQ(result.exit_code, 3);
  EXPECT_THAT(result.err, HasSubstr("the fixed and prescribed groups leave 3 rigid motions of the "
                                    "body free"));
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST(CliEndToEnd, BadMeshFileIsNamed) {
  TempFolder folder;
  json scene = bar_scene();
  scene["mesh"] = {{"file", "beam.msh"}};
  write_scene(folder, scene);
  write_text(folder.path() / "beam.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n");
  CliResult result = run_strata("run scene.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("beam.msh"));
  std::filesystem::remove(folder.path() / "beam.msh");
  result = run_strata("run scene.json", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("beam.msh"));
}

TEST(CliEndToEnd, InfoConvertAndHelp) {
  TempFolder folder;
  // One tet, gmsh 2.2, listed with negative orientation.
  write_text(folder.path() / "tet.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
             "4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 0 1 3 2 4\n$EndElements\n");
  CliResult result = run_strata("convert tet.msh tet.vtu", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(std::filesystem::exists(folder.path() / "tet.vtu"));
  result = run_strata("info tet.vtu", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("tet.vtu"));
  EXPECT_FALSE(result.out.empty());

  write_scene(folder, bar_scene());
  result = run_strata("info scene.json", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("44"));  // vertices of the box mesh

  result = run_strata("info nothing.msh", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("nothing.msh"));

  result = run_strata("--help", folder.path());
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_THAT(result.out, HasSubstr("run"));
  result = run_strata("run --help", folder.path());
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_THAT(result.out, HasSubstr("--set"));
}

}  // namespace
}  // namespace strata::cli_test
