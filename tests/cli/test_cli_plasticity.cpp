// End-to-end: a bracket bent beyond yield by a tip load that rises and comes back
// (material.plasticity, forces[].amplitude) keeps a permanent set that the purely elastic run does
// not; the run reports its plastic state in stats.json and in the .vtu frames.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "cli_test_utils.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;

/// A 1 × 0.1 × 0.1 m cantilever clamped at x = 0; a tip load of 3 kN (a clamp bending stress of
/// about 6·M/(b h²) = 18 MPa in beam theory, less on this coarse mesh, beyond σ_y = 4 MPa) applied
/// and removed over 12 load steps.
json bracket_scene(bool plastic) {
  json scene = json::parse(R"({
    "mesh": {"box": {"min": [0, 0, 0], "max": [1, 0.1, 0.1], "cells": [10, 2, 2]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e10, "poisson_ratio": 0.3,
                 "density": 1000},
    "fixed": [{"box": {"min": [0, 0, 0], "max": [0, 0.1, 0.1]}}],
    "forces": [{"region": {"plane": {"point": [1, 0, 0], "normal": [1, 0, 0]}},
                "total_force": [0, 0, -3000], "amplitude": [[0, 0], [0.5, 1], [1, 0]]}],
    "solver": {"mode": "static", "load_steps": 12},
    "output": {"probes": [[1, 0.05, 0.05]]}
  })");
  if (plastic) scene["material"]["plasticity"] = {{"yield_stress", 4e6}, {"hardening", 1e9}};
  return scene;
}

TEST(CliPlasticity, BentBeyondYieldTheBracketKeepsAPermanentSet) {
  TempFolder folder;
  write_text(folder.path() / "elastic.json", bracket_scene(false).dump(2));
  write_text(folder.path() / "plastic.json", bracket_scene(true).dump(2));
  const CliResult elastic = run_strata("run elastic.json --quiet", folder.path());
  ASSERT_EQ(elastic.exit_code, 0) << elastic.err;
  const CliResult plastic = run_strata("run plastic.json --quiet", folder.path());
  ASSERT_EQ(plastic.exit_code, 0) << plastic.err;

  const auto tip = [&](const std::string& name) {
    const Csv probes = read_csv(folder.path() / "out" / name / "probes.csv");
    std::vector<double> z;  // tip z displacement per frame
    for (const auto& row : probes.rows)
      z.push_back(row[row.size() - 1]);
    return z;
  };
  const std::vector<double> elastic_tip = tip("elastic");
  const std::vector<double> plastic_tip = tip("plastic");
  ASSERT_EQ(elastic_tip.size(), 13u);
  ASSERT_EQ(plastic_tip.size(), 13u);
  const double peak = std::abs(elastic_tip[6]);
  ASSERT_GT(peak, 0.0);
  EXPECT_LT(std::abs(elastic_tip.back()), 1e-6 * peak);  // elastic: back to rest
  EXPECT_GT(std::abs(plastic_tip[6]), peak);             // softer once it yields
  EXPECT_GT(std::abs(plastic_tip.back()), 0.02 * peak);  // a permanent set, downwards
  EXPECT_LT(plastic_tip.back(), 0.0);

  const json stats = read_json(folder.path() / "out" / "plastic" / "stats.json");
  ASSERT_TRUE(stats.contains("plasticity"));
  EXPECT_EQ(stats["plasticity"]["yield_stress"], 4e6);
  EXPECT_GT(stats["plasticity"]["largest_plastic_strain"].get<double>(), 0.0);
  EXPECT_GT(stats["plasticity"]["plastic_tets"].get<int>(), 0);
  EXPECT_EQ(stats["plasticity"]["unconverged_steps"], 0);
  EXPECT_GE(stats["plasticity"]["passes"].get<int>(), 12);
  EXPECT_FALSE(read_json(folder.path() / "out" / "elastic" / "stats.json").contains("plasticity"));
  const std::string frame = read_text(folder.path() / "out" / "plastic" / "plastic_000012.vtu");
  EXPECT_THAT(frame, ::testing::HasSubstr("Name=\"plastic_strain\""));
}

TEST(CliPlasticity, AdaptiveCutCarriesThePlasticStateLikeTheFullRun) {
  // One level of refinement: the adaptive run refines where the bracket yields, carries the
  // plastic state across its cut changes and ends where the full-resolution run ends. The cut
  // adapts however large it grows (full_resolution_fraction 1): the test follows it.
  TempFolder folder;
  json scene = bracket_scene(true);
  scene["hierarchy"] = {{"levels", 1}, {"full_resolution_fraction", 1.0}};
  scene["output"]["vtk"] = false;
  write_text(folder.path() / "bracket.json", scene.dump(2));
  const CliResult full = run_strata(
      "run bracket.json --quiet --out full --set hierarchy.mode=\"full\"", folder.path());
  ASSERT_EQ(full.exit_code, 0) << full.err;
  const CliResult adaptive = run_strata("run bracket.json --quiet --out adaptive", folder.path());
  ASSERT_EQ(adaptive.exit_code, 0) << adaptive.err;
  const Csv full_probes = read_csv(folder.path() / "full" / "probes.csv");
  const Csv adaptive_probes = read_csv(folder.path() / "adaptive" / "probes.csv");
  ASSERT_EQ(full_probes.rows.size(), adaptive_probes.rows.size());
  double peak = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < full_probes.rows.size(); ++i) {
    peak = std::max(peak, std::abs(full_probes.rows[i].back()));
    largest =
        std::max(largest, std::abs(full_probes.rows[i].back() - adaptive_probes.rows[i].back()));
  }
  ASSERT_GT(peak, 0.0);
  EXPECT_LT(largest, 0.02 * peak);  // the scene's hierarchy.tolerance is 0.01 of the same measure
  const json stats = read_json(folder.path() / "adaptive" / "stats.json");
  EXPECT_GT(stats["plasticity"]["plastic_tets"].get<int>(), 0);
  EXPECT_GT(stats["hierarchy"]["refinements"].get<int>(), 0);
  EXPECT_GT(std::abs(full_probes.rows.back().back()), 0.02 * peak);  // the permanent set
}

}  // namespace
}  // namespace strata::cli_test
