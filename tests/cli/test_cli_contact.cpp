// End-to-end: obstacles from the scene file — a block dropped on an implicit sphere (a level set)
// stays within the contact tolerance and reports its contacts, also on an adaptive cut, where it
// follows the full-resolution run; a block pressed onto a plane obstacle carries the load; the
// fine surface collides; `ground` is a plane obstacle with static friction; bad obstacle keys
// name their path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "cli_test_utils.hpp"
#include "surface_test_utils.hpp"

namespace strata::cli_test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json drop_scene() {
  return json::parse(R"({
    "mesh": {"box": {"min": [-0.05, -0.05, 0.22], "max": [0.05, 0.05, 0.32], "cells": [2, 2, 2]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "obstacles": [{"implicit": {"sphere": {"center": [0, 0, 0], "radius": 0.2}},
                   "voxel_size": 0.005, "friction": 0.3}],
    "solver": {"mode": "dynamic", "dt": 0.001, "duration": 0.3},
    "output": {"every": 50, "probes": [[0, 0, 0.22]]}
  })");
}

TEST(CliContact, BlockDroppedOnASphereStaysWithinTheTolerance) {
  TempFolder folder;
  write_text(folder.path() / "drop.json", drop_scene().dump(2));
  const CliResult result = run_strata("run drop.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const json stats = read_json(folder.path() / "out" / "drop" / "stats.json");
  ASSERT_TRUE(stats.contains("contact"));
  const double tolerance = stats["contact"]["tolerance"];
  EXPECT_NEAR(tolerance, 1e-3 * std::sqrt(3 * 0.01), 1e-12);  // 1e-3 × the block's diagonal
  EXPECT_GT(stats["contact"]["max_penetration"].get<double>(), 0.0);
  EXPECT_LE(stats["contact"]["max_penetration"].get<double>(), tolerance);
  EXPECT_EQ(stats["contact"]["active_contacts"].size(), 300u);
  EXPECT_GT(stats["contact"]["active_contacts"].back().get<int>(), 0);
  // The bottom centre rests on the sphere's top (z = 0.2), within the tolerance and the
  // level set's trilinear error.
  const Csv probes = read_csv(folder.path() / "out" / "drop" / "probes.csv");
  const double z = 0.22 + probes.rows.back()[7];
  EXPECT_NEAR(z, 0.2, tolerance + 1e-3);
  const std::string frame = read_text(folder.path() / "out" / "drop" / "drop_000006.vtu");
  EXPECT_THAT(frame, HasSubstr("Name=\"contact_force\""));
}

TEST(CliContact, PlaneObstacleCarriesTheLoadInStatics) {
  TempFolder folder;
  json scene = json::parse(R"({
    "mesh": {"box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1], "cells": [2, 2, 2]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "prescribed": [{"region": {"plane": {"point": [0, 0, 0.1], "normal": [0, 0, 1]}},
                    "displacement": [0, 0, -0.002]}],
    "obstacles": [{"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}],
    "solver": {"mode": "static", "load_steps": 2},
    "output": {"vtk": false}
  })");
  write_text(folder.path() / "press.json", scene.dump(2));
  const CliResult result = run_strata("run press.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Csv reactions = read_csv(folder.path() / "out" / "press" / "reactions.csv");
  const double pushed = reactions.rows.back()[4];  // fz of the prescribed top
  // 2 % compression of a laterally free block: about E · 0.02 · A = 200 N, pushing down.
  EXPECT_LT(pushed, -150.0);
  EXPECT_GT(pushed, -300.0);
  const json stats = read_json(folder.path() / "out" / "press" / "stats.json");
  EXPECT_LE(stats["contact"]["max_penetration"].get<double>(),
            stats["contact"]["tolerance"].get<double>());
}

TEST(CliContact, TheBoundFineSurfaceCollides) {
  // A cantilever meshed from a fine surface sags onto a plane 1 cm below it: the fine surface's
  // own vertices (bound to the coarser tets, some outside them) are contact points, so none of
  // them gets deeper into the plane than the tolerance.
  TempFolder folder;
  MatrixX3d surface;
  write_text(folder.path() / "bar.off", bar_off(surface));
  write_text(folder.path() / "scene.json", R"({
    "mesh": {"surface": "bar.off", "cell_size": 0.06, "facet_distance": 0.005},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"box": {"min": [-1, -1, -1], "max": [0.001, 1, 1]}}],
    "obstacles": [{"plane": {"point": [0, 0, -0.01], "normal": [0, 0, 1]}}],
    "solver": {"mode": "static", "load_steps": 4}
  })");
  const CliResult result = run_strata("run scene.json --quiet", folder.path());
  if (result.exit_code == 2 && result.err.find("not available") != std::string::npos)
    GTEST_SKIP() << "surface meshing not available yet: " << result.err;
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::filesystem::path out = folder.path() / "out" / "scene";
  const json stats = read_json(out / "stats.json");
  const double tolerance = stats["contact"]["tolerance"];
  EXPECT_EQ(stats["contact"]["surface_points"].get<Index>(), surface.rows());
  EXPECT_GT(stats["contact"]["points"].get<Index>(), surface.rows());
  EXPECT_LE(stats["contact"]["max_penetration"].get<double>(), tolerance);
  EXPECT_GT(stats["contact"]["active_contacts"].back().get<int>(), 0);
  const MatrixX3d last = read_vtp_points(out / "scene_surface_000004.vtp");
  ASSERT_EQ(last.rows(), surface.rows());
  EXPECT_GE(last.col(2).minCoeff(), -0.01 - tolerance);
  EXPECT_LT(last.col(2).minCoeff(), -0.01 + 0.002);  // it did land
}

TEST(CliContact, BadObstaclesNameTheirKey) {
  TempFolder folder;
  json scene = drop_scene();
  scene["obstacles"][0]["plane"] = {{"point", {0, 0, 0}}, {"normal", {0, 0, 1}}};
  write_text(folder.path() / "two.json", scene.dump(2));
  CliResult result = run_strata("run two.json --quiet", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(
      result.err,
      HasSubstr("obstacles.0: must have exactly one of plane, implicit, level_set, surface"));
  scene = drop_scene();
  scene["obstacles"][0]["friction"] = -1;
  write_text(folder.path() / "friction.json", scene.dump(2));
  result = run_strata("run friction.json --quiet", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("obstacles.0.friction: must be >= 0"));
  scene = drop_scene();
  scene["obstacles"][0]["implicit"]["sphere"]["radius"] = 0.3;  // the block starts inside
  write_text(folder.path() / "inside.json", scene.dump(2));
  result = run_strata("run inside.json --quiet", folder.path());
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("obstacles.0: contact point"));
}

TEST(CliContact, AdaptiveDropOnASphereFollowsFullResolution) {
  // The drop on the hierarchy: the adaptive run (levels 1, τ = 0.01) stays within the contact
  // tolerance, refines near the contact, and its probe follows the full-resolution run's. The cut
  // adapts however large it grows (full_resolution_fraction 1): the test follows it.
  TempFolder folder;
  for (const char* mode : {"full", "adaptive"}) {
    json scene = drop_scene();
    scene["solver"]["duration"] = 0.25;
    scene["output"]["every"] = 10;
    scene["hierarchy"] = {{"levels", 1}, {"mode", mode}, {"full_resolution_fraction", 1.0}};
    write_text(folder.path() / (std::string(mode) + ".json"), scene.dump(2));
    const CliResult result =
        run_strata(std::string("run ") + mode + ".json --quiet", folder.path());
    ASSERT_EQ(result.exit_code, 0) << result.err;
  }
  const json full = read_json(folder.path() / "out" / "full" / "stats.json");
  const json adaptive = read_json(folder.path() / "out" / "adaptive" / "stats.json");
  for (const json* stats : {&full, &adaptive}) {
    ASSERT_TRUE(stats->contains("contact"));
    EXPECT_GT((*stats)["contact"]["max_penetration"].get<double>(), 0.0);  // it landed
    EXPECT_LE((*stats)["contact"]["max_penetration"].get<double>(),
              (*stats)["contact"]["tolerance"].get<double>());
    EXPECT_EQ((*stats)["contact"]["active_contacts"].size(), 250u);
  }
  EXPECT_EQ(full["contact"]["barrier_stiffness"], adaptive["contact"]["barrier_stiffness"]);
  EXPECT_GT(adaptive["hierarchy"]["refinements"].get<int>(), 0);
  const Csv a = read_csv(folder.path() / "out" / "adaptive" / "probes.csv");
  const Csv f = read_csv(folder.path() / "out" / "full" / "probes.csv");
  ASSERT_EQ(a.rows.size(), f.rows.size());
  double largest = 0.0, difference = 0.0;
  for (size_t r = 0; r < f.rows.size(); ++r) {
    const Vector3d uf(f.rows[r][5], f.rows[r][6], f.rows[r][7]);
    const Vector3d ua(a.rows[r][5], a.rows[r][6], a.rows[r][7]);
    largest = std::max(largest, uf.norm());
    difference = std::max(difference, (ua - uf).norm());
  }
  EXPECT_GT(largest, 0.01);  // it fell about 2 cm
  EXPECT_LT(difference, 0.02 * largest);
}

TEST(CliContact, AnIndentingSphereBetweenTheCoarseVerticesIsFeltOnTheHierarchy) {
  // A block pressed by its top face onto a rigid sphere whose top lies between the vertices of
  // the coarse mesh (3.2 mm below the nearest one), static, 2 levels, with nothing but `levels`
  // set in `hierarchy`. The finest level's boundary vertices are the contact points of every cut,
  // so the first load step already presses on the sphere, the cut refines (on this small block
  // past full_resolution_fraction, to full resolution) and the probe on the contact point
  // follows full resolution within the tolerance. With the coarse cut's
  // boundary vertices alone (`finest_contact_points` false) the first load step misses the
  // sphere, the body moves rigidly (an estimate of 0) and the probe is far off.
  TempFolder folder;
  const auto write_scene = [&](const std::string& name, const json& hierarchy,
                               double friction = 0.0) {
    json scene = json::parse(R"({
      "mesh": {"box": {"min": [0, 0, 0], "max": [0.3, 0.3, 0.1], "cells": [3, 3, 1]}},
      "material": {"model": "neohookean", "youngs_modulus": 3e5, "poisson_ratio": 0.4,
                   "density": 1000},
      "obstacles": [{"implicit": {"sphere": {"center": [0.12, 0.17, -0.2], "radius": 0.2}},
                     "voxel_size": 0.004}],
      "prescribed": [{"region": {"plane": {"point": [0, 0, 0.1], "normal": [0, 0, 1]}},
                      "displacement": [0, 0, -0.008]}],
      "solver": {"mode": "static", "load_steps": 4},
      "output": {"every": 1, "vtk": false, "probes": [[0.12, 0.17, 0.0], [0.15, 0.15, 0.05]]}
    })");
    scene["hierarchy"] = hierarchy;
    scene["obstacles"][0]["friction"] = friction;
    write_text(folder.path() / (name + ".json"), scene.dump(2));
    const CliResult result = run_strata("run " + name + ".json --quiet", folder.path());
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return read_json(folder.path() / "out" / name / "stats.json");
  };
  const json full = write_scene("full", {{"levels", 2}, {"mode", "full"}});
  const json finest = write_scene("finest", {{"levels", 2}});
  const json vertices = write_scene("vertices", {{"levels", 2}, {"finest_contact_points", false}});
  EXPECT_FALSE(full["contact"]["finest_boundary_points"].get<bool>());
  EXPECT_TRUE(finest["contact"]["finest_boundary_points"].get<bool>());
  EXPECT_FALSE(vertices["contact"]["finest_boundary_points"].get<bool>());
  // 3 × 3 × 1 cells: 2 · (9 + 3 + 3) = 30 squares, 2 triangles each, 16 finest per triangle: a
  // closed surface of F = 960 triangles has 2 + F / 2 vertices.
  EXPECT_EQ(finest["contact"]["points"].get<int>(), 2 + 16 * 2 * 2 * 15 / 2);
  EXPECT_GT(finest["contact"]["active_contacts"][0].get<int>(), 0);
  EXPECT_EQ(vertices["contact"]["active_contacts"][0].get<int>(), 0);
  const auto out_error = [&](const std::string& name, const std::string& full_name = "full") {
    return probe_error(folder.path() / "out" / name, folder.path() / "out" / full_name);
  };
  EXPECT_LT(out_error("finest"), 0.01);
  EXPECT_GT(out_error("vertices"), 0.05);
  // With friction (μ = 0.3) the passes that re-solve the first load step on finer cuts measure
  // slip from the start of the load step, not from the coarser pass's solution (which held the
  // contact where the coarse cut had put it: 5.6 % off before).
  write_scene("full_friction", {{"levels", 2}, {"mode", "full"}}, 0.3);
  write_scene("friction", {{"levels", 2}}, 0.3);
  EXPECT_LT(out_error("friction", "full_friction"), 0.01);
}

TEST(CliContact, TheArmadilloDroppedOnTheGroundStaysWithinTheTolerance) {
  // The armadillo scan (26,002 vertices) meshed coarsely, on an adaptive cut, dropped 26 mm onto
  // the ground: its fine surface's vertices are contact points through the tree, and none of
  // them gets deeper than the tolerance.
  const std::filesystem::path model = std::filesystem::path(STRATA_MODELS_DIR) / "armadillo.off";
  if (!std::filesystem::exists(model)) GTEST_SKIP() << "no armadillo.off";
  TempFolder folder;
  json scene = json::parse(R"({
    "mesh": {"cell_size": 20},
    "material": {"model": "neohookean", "youngs_modulus": 5000, "poisson_ratio": 0.4,
                 "density": 1e-6, "damping": {"mass": 2.0}},
    "gravity": [0, -9810, 0],
    "ground": {"point": [0, -80, 0], "normal": [0, 1, 0], "friction": 0.5},
    "solver": {"mode": "dynamic", "dt": 0.005, "duration": 0.12},
    "output": {"every": 6},
    "hierarchy": {"levels": 1, "tolerance": 0.05}
  })");
  scene["mesh"]["surface"] = model.string();
  write_text(folder.path() / "drop.json", scene.dump(2));
  const CliResult result = run_strata("run drop.json --quiet", folder.path());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::filesystem::path out = folder.path() / "out" / "drop";
  const json stats = read_json(out / "stats.json");
  ASSERT_TRUE(stats.contains("contact"));
  const double tolerance = stats["contact"]["tolerance"];
  EXPECT_EQ(stats["contact"]["surface_points"].get<Index>(), 26002);
  EXPECT_GT(stats["contact"]["max_penetration"].get<double>(), 0.0);  // it landed
  EXPECT_LE(stats["contact"]["max_penetration"].get<double>(), tolerance);
  EXPECT_GT(stats["contact"]["active_contacts"].back().get<int>(), 0);
  // The fine surface as written: no vertex below the ground by more than the tolerance.
  const MatrixX3d last = read_vtp_points(out / "drop_surface_000004.vtp");
  ASSERT_EQ(last.rows(), 26002);
  EXPECT_GE(last.col(1).minCoeff(), -80.0 - tolerance);
  EXPECT_LT(last.col(1).minCoeff(), -80.0 + 1.0);
  EXPECT_THAT(read_text(out / "drop_surface_000004.vtp"), HasSubstr("Name=\"contact_force\""));
}

TEST(CliContact, GroundIsAPlaneObstacleThatHoldsStaticFriction) {
  // `ground` is the plane obstacle: a cube on it with μ = 0.5 (friction angle 26.6°) under gravity
  // tilted by 15° stays put (drift below the contact tolerance, as on an `obstacles` plane);
  // tilted by 35° it slides with g (sin θ − μ cos θ) within 2 %.
  TempFolder folder;
  for (const double degrees : {15.0, 35.0}) {
    const double theta = degrees * M_PI / 180.0;
    json scene = json::parse(R"({
      "mesh": {"box": {"min": [-0.05, -0.05, 0], "max": [0.05, 0.05, 0.1], "cells": [1, 1, 1]}},
      "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                   "density": 1000},
      "ground": {"point": [0, 0, 0], "normal": [0, 0, 1], "friction": 0.5},
      "solver": {"mode": "dynamic", "dt": 0.001, "duration": 0.35},
      "output": {"vtk": false, "probes": [[0, 0, 0.05]]}
    })");
    scene["gravity"] = {9.81 * std::sin(theta), 0.0, -9.81 * std::cos(theta)};
    const std::string name = "tilt" + std::to_string(static_cast<int>(degrees));
    write_text(folder.path() / (name + ".json"), scene.dump(2));
    const CliResult result = run_strata("run " + name + ".json --quiet", folder.path());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const json stats = read_json(folder.path() / "out" / name / "stats.json");
    ASSERT_TRUE(stats.contains("contact"));
    const double tolerance = stats["contact"]["tolerance"];
    EXPECT_LE(stats["contact"]["max_penetration"].get<double>(), tolerance);
    const Csv probes = read_csv(folder.path() / "out" / name / "probes.csv");
    // Columns: time, probe, x, y, z, ux, uy, uz (centre of the cube).
    double drift = 0.0, v1 = 0.0, t1 = 0.0, u_prev = 0.0, t_prev = 0.0;
    for (const auto& row : probes.rows) {
      drift = std::max(drift, std::abs(row[5]));
      const double v = row[0] > t_prev ? (row[5] - u_prev) / (row[0] - t_prev) : 0.0;
      if (std::abs(row[0] - 0.15) < 1e-9) {
        v1 = v;
        t1 = row[0];
      }
      u_prev = row[5];
      t_prev = row[0];
    }
    if (degrees < 26.0) {
      EXPECT_LT(drift, tolerance) << degrees;
    } else {
      const auto& last = probes.rows.back();
      const auto& before = probes.rows[probes.rows.size() - 2];
      const double v_end = (last[5] - before[5]) / (last[0] - before[0]);
      const double a = (v_end - v1) / (t_prev - t1);
      const double expected = 9.81 * (std::sin(theta) - 0.5 * std::cos(theta));
      EXPECT_NEAR(a, expected, 0.02 * expected);
    }
  }
}

}  // namespace
}  // namespace strata::cli_test
