// `strata precompute` and hierarchy mode "precomputed" end to end: the cut file, playback against
// full resolution and the adaptive run it was recorded from, an unseen load, the conforming mesh,
// and the errors for bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cli_test_utils.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

/// A 1 × 1 × 0.25 m slab fixed at the bottom and pressed by a patch on top (dynamic, implicit).
json slab(double patch_x) {
  json scene = json::parse(R"({
    "mesh": {"box": {"min": [0, 0, 0], "max": [1, 1, 0.25], "cells": [4, 4, 1]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000, "damping": {"mass": 20.0}},
    "fixed": [{"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}],
    "forces": [{"region": {"box": {"min": [0.4, 0.4, 0.25], "max": [0.6, 0.6, 0.25]}},
                "total_force": [0, 0, -2000]}],
    "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.005, "duration": 0.05},
    "output": {"every": 2, "vtk": false,
               "probes": [[0.5, 0.5, 0.25], [0.3, 0.5, 0.25], [0.1, 0.1, 0.25]]},
    "hierarchy": {"levels": 2, "tolerance": 0.05}
  })");
  scene["forces"][0]["region"]["box"]["min"][0] = patch_x - 0.1;
  scene["forces"][0]["region"]["box"]["max"][0] = patch_x + 0.1;
  return scene;
}

CliResult run_in(const TempFolder& folder, const std::string& arguments) {
  return run_strata(arguments, folder.path());
}

TEST(CliPrecompute, PlaysBackTheCutOfItsRunsAndWritesAConformingMesh) {
  const TempFolder folder;
  write_text(folder.path() / "train.json", slab(0.5).dump(2));
  const CliResult pre = run_in(
      folder, "precompute train.json --out cut.json --tolerance 0.05 --windows 2 --mesh cut.vtu");
  ASSERT_EQ(pre.exit_code, 0) << pre.err;
  EXPECT_THAT(pre.out, HasSubstr("wrote cut.json: 2 windows"));
  const json cut = read_json(folder.path() / "cut.json");
  EXPECT_EQ(cut["format"], "strata precomputed cut");
  EXPECT_EQ(cut["windows"].size(), 2u);
  EXPECT_EQ(cut["sources"], json::array({"train"}));
  EXPECT_TRUE(std::filesystem::exists(folder.path() / "cut_runs" / "train" / "stats.json"));

  // Playback on the training scene: at least as fine as the adaptive run at every step, so no
  // less accurate than it against full resolution.
  ASSERT_EQ(
      run_in(folder, "run train.json -q --out full --set hierarchy.mode='\"full\"'").exit_code, 0);
  ASSERT_EQ(run_in(folder, "run train.json -q --out adaptive").exit_code, 0);
  const CliResult played =
      run_in(folder,
             "run train.json -q --out played --set hierarchy.mode='\"precomputed\"' "
             "--set hierarchy.cut='\"cut.json\"'");
  ASSERT_EQ(played.exit_code, 0) << played.err;
  const json stats = read_json(folder.path() / "played" / "stats.json");
  EXPECT_EQ(stats["hierarchy"]["mode"], "precomputed");
  EXPECT_EQ(stats["hierarchy"]["precomputed"]["windows"], 2);
  const double adaptive_error = probe_error(folder.path() / "adaptive", folder.path() / "full");
  const double played_error = probe_error(folder.path() / "played", folder.path() / "full");
  EXPECT_GT(adaptive_error, 0.0);
  EXPECT_LE(played_error, 1.1 * adaptive_error) << adaptive_error;
  const json full_stats = read_json(folder.path() / "full" / "stats.json");
  EXPECT_LT(stats["tets"].get<double>(), full_stats["tets"].get<double>());

  // The conforming mesh: a valid mesh of the same volume that a plain scene runs on.
  const CliResult info = run_in(folder, "info cut.vtu");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_THAT(info.out, HasSubstr("volume            0.25"));
  json plain = slab(0.5);
  plain.erase("hierarchy");
  plain["mesh"] = {{"file", "cut.vtu"}};
  write_text(folder.path() / "plain.json", plain.dump(2));
  const CliResult on_mesh = run_in(folder, "run plain.json -q --out plain");
  ASSERT_EQ(on_mesh.exit_code, 0) << on_mesh.err;
  // Not the cut's own discretisation (its hanging vertices are now free), but close to it.
  EXPECT_LT(probe_error(folder.path() / "plain", folder.path() / "full"), 0.2);
}

TEST(CliPrecompute, AnUnseenLoadIsReportedWhenTheCutMissesIt) {
  const TempFolder folder;
  write_text(folder.path() / "train.json", slab(0.3).dump(2));
  json far = slab(0.8);
  far["hierarchy"] = {
      {"levels", 2}, {"mode", "precomputed"}, {"cut", "cut.json"}, {"tolerance", 0.01}};
  write_text(folder.path() / "far.json", far.dump(2));
  ASSERT_EQ(run_in(folder, "precompute train.json --out cut.json -q").exit_code, 0);
  const CliResult played = run_in(folder, "run far.json -q");
  ASSERT_EQ(played.exit_code, 0) << played.err;
  EXPECT_THAT(played.err, HasSubstr("on the precomputed cut cut.json: it does not capture"));
  const json stats = read_json(folder.path() / "out" / "far" / "stats.json");
  EXPECT_FALSE(stats["hierarchy"]["tolerance_met"].get<bool>());
}

TEST(CliPrecompute, BadInputGetsOneLineErrors) {
  const TempFolder folder;
  write_text(folder.path() / "train.json", slab(0.5).dump(2));
  json no_tree = slab(0.5);
  no_tree.erase("hierarchy");
  write_text(folder.path() / "plain.json", no_tree.dump(2));
  json other_mesh = slab(0.5);
  other_mesh["mesh"]["box"]["cells"] = {2, 2, 1};
  write_text(folder.path() / "other.json", other_mesh.dump(2));
  const auto error = [&](const std::string& arguments) {
    const CliResult result = run_in(folder, arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments << "\n" << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    return result.err;
  };
  EXPECT_THAT(error("precompute plain.json --out cut.json"), HasSubstr("needs a \"hierarchy\""));
  EXPECT_THAT(error("precompute train.json --out cut.txt"), HasSubstr("must be a .json file"));
  EXPECT_THAT(error("precompute train.json other.json --out cut.json -q"),
              HasSubstr("its mesh differs from that of train.json"));
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "cut.json"));

  ASSERT_EQ(run_in(folder, "precompute train.json --out cut.json -q").exit_code, 0);
  const std::string precomputed = " --set hierarchy.mode='\"precomputed\"'";
  EXPECT_THAT(error("run train.json -q" + precomputed), HasSubstr("needs \"cut\""));
  EXPECT_THAT(error("run train.json -q --set hierarchy.cut='\"cut.json\"'"),
              HasSubstr("hierarchy.cut: only with mode \"precomputed\""));
  // The full-resolution reference of a precomputed scene ignores its cut.
  const CliResult full = run_in(
      folder,
      "run train.json -q --set hierarchy.mode='\"full\"' --set hierarchy.cut='\"cut.json\"'");
  EXPECT_EQ(full.exit_code, 0) << full.err;
  EXPECT_THAT(full.err,
              HasSubstr("hierarchy.cut: mode \"full\" plays back no precomputed cut (ignored)"));
  EXPECT_THAT(error("run other.json -q" + precomputed + " --set hierarchy.cut='\"cut.json\"'"),
              HasSubstr("hierarchy.cut (cut.json): made for a coarse mesh of 50 vertices"));
  EXPECT_THAT(error("run train.json -q" + precomputed + " --set hierarchy.cut='\"none.json\"'"),
              HasSubstr("train.json: hierarchy.cut: "));
  EXPECT_THAT(error("run train.json -q" + precomputed + " --set hierarchy.cut='\"none.json\"'"),
              HasSubstr("none.json: cannot open"));
  json cut = read_json(folder.path() / "cut.json");
  cut["windows"][0]["refined"].push_back("3.9");
  write_text(folder.path() / "bad.json", cut.dump());
  EXPECT_THAT(error("run train.json -q" + precomputed + " --set hierarchy.cut='\"bad.json\"'"),
              HasSubstr("bad.json: windows.0.refined."));
  EXPECT_THAT(error("run train.json -q" + precomputed + " --set hierarchy.cut='\"bad.json\"'"),
              HasSubstr("is not a node path"));
  // A cut belongs to one tree: its levels and its keys are checked.
  cut = read_json(folder.path() / "cut.json");
  cut["extra"] = 1;
  write_text(folder.path() / "extra.json", cut.dump());
  EXPECT_THAT(error("run train.json -q" + precomputed + " --set hierarchy.cut='\"extra.json\"'"),
              HasSubstr("extra.json: extra: unknown key"));
  EXPECT_THAT(error("run train.json -q --set hierarchy.levels=1" + precomputed +
                    " --set hierarchy.cut='\"cut.json\"'"),
              HasSubstr("hierarchy.levels: is 1, and the cut 'cut.json' was recorded with 2 "
                        "levels"));
  // --tolerance 0 is not a tolerance, and a window holds at least one step (the slab takes 10).
  EXPECT_THAT(error("precompute train.json --out c2.json -q --tolerance 0"),
              HasSubstr("--tolerance: must be in (0, 1), got 0"));
  EXPECT_THAT(error("precompute train.json --out c2.json -q --windows 11"),
              HasSubstr("--windows 11 exceeds the 10 steps of the longest run"));
  EXPECT_THAT(error("precompute train.json --out c2.json -q --windows 1000000000"),
              HasSubstr("--windows: must be between 1 and 1000000"));
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "c2.json"));
}

}  // namespace
}  // namespace strata::cli_test
