// Scene parser: valid scenes convert to the right values; every error names the key path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli_test_utils.hpp"
#include "strata/app/scene_parser.hpp"

namespace strata::app {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json minimal_scene() {
  return json::parse(R"({
    "mesh": {"box": {"min": [0, 0, 0], "max": [1, 0.1, 0.1], "cells": [4, 1, 1]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                 "density": 1000},
    "fixed": [{"box": {"min": [0, 0, 0], "max": [0, 0.1, 0.1]}}],
    "solver": {"mode": "static"}
  })");
}

/// The message of the InputError that parsing `scene` throws ("" if none).
std::string parse_error(const json& scene) {
  try {
    parse_scene(scene, "scene.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SceneParser, MinimalSceneGetsDefaults) {
  const Scene scene = parse_scene(minimal_scene(), "dir/beam.json");
  EXPECT_EQ(scene.name, "beam");
  EXPECT_FALSE(scene.mesh.file.has_value());
  EXPECT_EQ(scene.mesh.box_cells, (std::array<int, 3>{4, 1, 1}));
  EXPECT_EQ(scene.material.model, MaterialModel::neohookean);
  EXPECT_DOUBLE_EQ(scene.material.youngs_modulus, 1e6);
  EXPECT_DOUBLE_EQ(scene.material.mass_damping, 0.0);
  EXPECT_DOUBLE_EQ(scene.material.stiffness_damping, 0.0);
  EXPECT_EQ(scene.gravity, Vector3d::Zero());
  ASSERT_EQ(scene.fixed.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<BoxRegion>(scene.fixed[0].region));
  EXPECT_EQ(scene.fixed[0].name, "fixed.0");
  EXPECT_EQ(scene.fixed[0].kind, DirichletKind::fixed);
  EXPECT_EQ(scene.solver.mode, SimulationMode::static_equilibrium);
  EXPECT_EQ(scene.solver.load_steps, 10);
  EXPECT_EQ(scene.output.every, 1);
  EXPECT_TRUE(scene.output.vtk);
  EXPECT_TRUE(scene.output.probes.empty());
  EXPECT_FALSE(scene.ground.has_value());
}

TEST(SceneParser, FullSceneValues) {
  json scene = minimal_scene();
  scene["mesh"] = {{"file", "meshes/beam.msh"}};
  scene["material"]["damping"] = {{"mass", 0.5}, {"stiffness", 0.01}};
  scene["gravity"] = {0, 0, -9.81};
  scene["prescribed"] = json::parse(R"([
    {"region": {"plane": {"point": [1, 0, 0], "normal": [2, 0, 0], "tolerance": 0.01}},
     "displacement": [0.1, 0, 0]},
    {"region": {"sphere": {"center": [1, 0, 0], "radius": 0.2}},
     "rotation": {"axis": [0, 0, 3], "center": [1, 0.05, 0.05], "angle_degrees": 90}}])");
  scene["forces"] = json::parse(R"([{"region": {"box": {"min": [1,0,0], "max": [1,0.1,0.1]}},
                                     "total_force": [0, 0, -100]}])");
  scene["ground"] = json::parse(R"({"point": [0, 0, -1], "normal": [0, 0, 2], "friction": 0.3})");
  scene["solver"] =
      json::parse(R"({"mode": "dynamic", "integrator": "rk4", "dt": 1e-4, "duration": 0.5})");
  scene["output"] = json::parse(R"({"every": 5, "probes": [[1, 0.05, 0.05]], "vtk": false})");

  const Scene parsed = parse_scene(scene, "dir/beam.json");
  ASSERT_TRUE(parsed.mesh.file.has_value());
  EXPECT_EQ(*parsed.mesh.file, std::filesystem::path("dir/meshes/beam.msh"));
  EXPECT_DOUBLE_EQ(parsed.material.mass_damping, 0.5);
  EXPECT_DOUBLE_EQ(parsed.material.stiffness_damping, 0.01);
  EXPECT_EQ(parsed.gravity, Vector3d(0, 0, -9.81));
  ASSERT_EQ(parsed.prescribed.size(), 2u);
  const auto& plane = std::get<PlaneRegion>(parsed.prescribed[0].region);
  EXPECT_DOUBLE_EQ(plane.distance, 0.01);
  EXPECT_EQ(parsed.prescribed[0].kind, DirichletKind::displacement);
  EXPECT_EQ(parsed.prescribed[1].name, "prescribed.1");
  EXPECT_EQ(parsed.prescribed[0].displacement, Vector3d(0.1, 0, 0));
  EXPECT_EQ(parsed.prescribed[1].kind, DirichletKind::rotation);
  EXPECT_TRUE(parsed.prescribed[1].has_center);
  EXPECT_EQ(parsed.prescribed[1].center, Vector3d(1, 0.05, 0.05));
  EXPECT_TRUE(parsed.prescribed[1].axis.isApprox(Vector3d::UnitZ()));
  EXPECT_DOUBLE_EQ(parsed.prescribed[1].angle, std::acos(0.0));
  EXPECT_EQ(parsed.forces.at(0).total_force, Vector3d(0, 0, -100));
  EXPECT_EQ(parsed.forces.at(0).name, "forces.0");
  ASSERT_EQ(parsed.dirichlet_groups().size(), 3u);
  EXPECT_EQ(parsed.dirichlet_groups()[0].name, "fixed.0");
  EXPECT_EQ(parsed.dirichlet_groups()[2].name, "prescribed.1");
  ASSERT_TRUE(parsed.ground.has_value());
  EXPECT_TRUE(parsed.ground->normal.isApprox(Vector3d::UnitZ()));
  EXPECT_DOUBLE_EQ(parsed.ground->friction, 0.3);
  EXPECT_EQ(parsed.solver.integrator, Integrator::rk4);
  EXPECT_DOUBLE_EQ(parsed.solver.dt, 1e-4);
  EXPECT_DOUBLE_EQ(parsed.solver.duration, 0.5);
  EXPECT_EQ(parsed.output.every, 5);
  EXPECT_FALSE(parsed.output.vtk);
  ASSERT_EQ(parsed.output.probes.size(), 1u);
}

TEST(SceneParser, UnknownKeysNameTheirPath) {
  json scene = minimal_scene();
  scene["output"] = {{"probs", json::array()}};
  EXPECT_EQ(parse_error(scene), "scene.json: output.probs: unknown key");
  scene = minimal_scene();
  scene["fixed"][0]["box"]["maxx"] = {1, 1, 1};
  EXPECT_EQ(parse_error(scene), "scene.json: fixed.0.box.maxx: unknown key");
  scene = minimal_scene();
  scene["gravitation"] = {0, 0, -9.81};
  EXPECT_EQ(parse_error(scene), "scene.json: gravitation: unknown key");
}

TEST(SceneParser, MissingRequiredKeys) {
  for (const char* key : {"youngs_modulus", "poisson_ratio", "density", "model"}) {
    json scene = minimal_scene();
    scene["material"].erase(key);
    EXPECT_EQ(parse_error(scene),
              std::string("scene.json: material.") + key + ": missing required key");
  }
  json scene = minimal_scene();
  scene.erase("mesh");
  EXPECT_EQ(parse_error(scene), "scene.json: mesh: missing required key");
  scene = minimal_scene();
  scene["solver"] = {{"mode", "dynamic"}, {"dt", 1e-3}};
  EXPECT_EQ(parse_error(scene), "scene.json: solver.duration: missing required key");
}

TEST(SceneParser, WrongTypes) {
  json scene = minimal_scene();
  scene["material"]["youngs_modulus"] = "1e6";
  EXPECT_EQ(parse_error(scene),
            "scene.json: material.youngs_modulus: must be a number, got a string");
  scene = minimal_scene();
  scene["gravity"] = {0, -9.81};
  EXPECT_EQ(parse_error(scene), "scene.json: gravity: must be an array of 3 numbers");
  scene = minimal_scene();
  scene["output"] = {{"vtk", 1}};
  EXPECT_EQ(parse_error(scene),
            "scene.json: output.vtk: must be true, false or \"surface\", got a number");
  scene = minimal_scene();
  scene["output"] = {{"vtk", "yes"}};
  EXPECT_EQ(parse_error(scene),
            "scene.json: output.vtk: must be true, false or \"surface\", got \"yes\"");
  scene = minimal_scene();
  scene["mesh"]["box"]["cells"] = {4, 1.5, 1};
  EXPECT_EQ(parse_error(scene), "scene.json: mesh.box.cells.1: must be an integer");
  scene = minimal_scene();
  scene["fixed"] = json::array({{{"box", {{"min", {0, 0, 0}}, {"max", {0, 0, "a"}}}}}});
  EXPECT_EQ(parse_error(scene), "scene.json: fixed.0.box.max: must be an array of 3 numbers");
  EXPECT_THAT(parse_error(json::array()), HasSubstr("scene.json: scene: must be an object"));
}

TEST(SceneParser, OutOfRangeValues) {
  json scene = minimal_scene();
  scene["material"]["poisson_ratio"] = 0.5;
  EXPECT_EQ(parse_error(scene), "scene.json: material.poisson_ratio: must be in [0, 0.5)");
  scene["material"]["poisson_ratio"] = -0.1;
  EXPECT_EQ(parse_error(scene), "scene.json: material.poisson_ratio: must be in [0, 0.5)");
  scene = minimal_scene();
  scene["material"]["youngs_modulus"] = 0;
  EXPECT_EQ(parse_error(scene), "scene.json: material.youngs_modulus: must be > 0");
  scene = minimal_scene();
  scene["material"]["damping"] = {{"mass", -1}};
  EXPECT_EQ(parse_error(scene), "scene.json: material.damping.mass: must be >= 0");
  scene = minimal_scene();
  scene["solver"]["load_steps"] = 0;
  EXPECT_EQ(parse_error(scene), "scene.json: solver.load_steps: must be >= 1");
  scene = minimal_scene();
  scene["output"] = {{"every", 0}};
  EXPECT_EQ(parse_error(scene), "scene.json: output.every: must be >= 1");
  scene = minimal_scene();
  scene["mesh"]["box"]["max"] = {1, 0, 1};
  EXPECT_EQ(parse_error(scene), "scene.json: mesh.box.max: must be > min in every coordinate");
  scene = minimal_scene();
  scene["ground"] = {{"point", {0, 0, 0}}, {"normal", {0, 0, 0}}};
  EXPECT_EQ(parse_error(scene), "scene.json: ground.normal: must not be the zero vector");
}

TEST(SceneParser, PlasticityAndLoadHistories) {
  json scene = minimal_scene();
  scene["material"]["plasticity"] = {{"yield_stress", 2e5}, {"hardening", 1e5}};
  scene["forces"] = json::parse(R"([{"region": {"sphere": {"center": [1, 0, 0], "radius": 0.1}},
                                     "total_force": [0, 0, -1],
                                     "amplitude": [[0, 0], [0.5, 1], [1, 0]]}])");
  scene["prescribed"] = json::parse(R"([{"region": {"plane": {"point": [1, 0, 0],
                                                              "normal": [1, 0, 0]}},
                                         "displacement": [0.01, 0, 0],
                                         "amplitude": [[0.2, 1]]}])");
  scene["solver"]["max_plastic_passes"] = 7;
  scene["solver"]["plastic_tolerance"] = 1e-4;
  const Scene parsed = parse_scene(scene, "scene.json");
  ASSERT_TRUE(parsed.material.plasticity.has_value());
  EXPECT_EQ(parsed.material.plasticity->yield_stress, 2e5);
  EXPECT_EQ(parsed.material.plasticity->hardening, 1e5);
  EXPECT_TRUE(std::isinf(parsed.material.plasticity->max_plastic_strain));
  ASSERT_EQ(parsed.forces.size(), 1u);
  ASSERT_EQ(parsed.forces[0].amplitude.points.size(), 3u);
  EXPECT_EQ(parsed.forces[0].amplitude.value(0.25), 0.5);
  EXPECT_EQ(parsed.forces[0].amplitude.value(2.0), 0.0);
  ASSERT_EQ(parsed.prescribed.size(), 1u);
  EXPECT_EQ(parsed.prescribed[0].amplitude.value(0.0), 1.0);  // constant beyond the ends
  EXPECT_EQ(parsed.solver.plasticity.max_passes, 7);
  EXPECT_EQ(parsed.solver.plasticity.tolerance, 1e-4);
  EXPECT_FALSE(parse_scene(minimal_scene(), "scene.json").material.plasticity.has_value());
}

TEST(SceneParser, BadPlasticityAndLoadHistoriesNameTheKey) {
  json scene = minimal_scene();
  scene["material"]["plasticity"] = {{"yield_stress", -1}};
  EXPECT_EQ(parse_error(scene), "scene.json: material.plasticity.yield_stress: must be > 0");
  scene["material"]["plasticity"] = {{"yield_stress", 1e5}, {"hardening", -1}};
  EXPECT_EQ(parse_error(scene), "scene.json: material.plasticity.hardening: must be >= 0");
  scene["material"]["plasticity"] = {{"yield_stress", 1e5}, {"softening", 1}};
  EXPECT_THAT(parse_error(scene), HasSubstr("material.plasticity.softening"));
  scene["material"]["plasticity"] = {{"hardening", 1}};
  EXPECT_THAT(parse_error(scene), HasSubstr("material.plasticity.yield_stress"));
  scene = minimal_scene();
  scene["forces"] = json::parse(R"([{"region": {"sphere": {"center": [1, 0, 0], "radius": 0.1}},
                                     "total_force": [0, 0, -1],
                                     "amplitude": [[0, 0], [0, 1]]}])");
  EXPECT_EQ(parse_error(scene), "scene.json: forces.0.amplitude.1.0: times must increase strictly");
  scene["forces"][0]["amplitude"] = json::parse("[[0, 0, 1]]");
  EXPECT_EQ(parse_error(scene), "scene.json: forces.0.amplitude.0: must be a pair [t, s]");
  scene["forces"][0]["amplitude"] = json::array();
  EXPECT_EQ(parse_error(scene),
            "scene.json: forces.0.amplitude: must hold at least one point [t, s]");
  scene["forces"][0]["amplitude"] = json::parse(R"([[0, "a"]])");
  EXPECT_THAT(parse_error(scene), HasSubstr("forces.0.amplitude.0.1: must be a number"));
  scene = minimal_scene();
  scene["solver"]["max_plastic_passes"] = 0;
  EXPECT_EQ(parse_error(scene), "scene.json: solver.max_plastic_passes: must be >= 1");
}

TEST(SceneParser, SurfaceSprings) {
  json scene = minimal_scene();
  scene["material"]["surface_springs"] = {
      {"youngs_modulus", 1e5}, {"yield_strain", 0.01}, {"fraction", 0.25}, {"seed", 4}};
  const Scene parsed = parse_scene(scene, "scene.json");
  ASSERT_TRUE(parsed.surface_springs.has_value());
  EXPECT_EQ(parsed.surface_springs->youngs_modulus, 1e5);
  EXPECT_EQ(parsed.surface_springs->yield_strain, 0.01);
  EXPECT_EQ(parsed.surface_springs->fraction, 0.25);
  EXPECT_EQ(parsed.surface_springs->seed, 4u);
  EXPECT_FALSE(parse_scene(minimal_scene(), "scene.json").surface_springs.has_value());
  scene["material"]["surface_springs"]["fraction"] = 1.5;
  EXPECT_EQ(parse_error(scene), "scene.json: material.surface_springs.fraction: must be in (0, 1]");
  scene["material"]["surface_springs"] = {{"yield_strain", 0.01}};
  EXPECT_THAT(parse_error(scene), HasSubstr("material.surface_springs.youngs_modulus"));
  scene["material"]["surface_springs"] = {{"youngs_modulus", 1e5}};
  scene["hierarchy"] = {{"levels", 1}};
  EXPECT_EQ(parse_error(scene),
            "scene.json: material.surface_springs: not supported with hierarchy (the springs "
            "live on one mesh's surface)");
}

TEST(SceneParser, UnknownEnumValuesListTheChoices) {
  json scene = minimal_scene();
  scene["solver"] = {{"mode", "dynamic"}, {"integrator", "rk5"}, {"dt", 1e-3}, {"duration", 1}};
  EXPECT_EQ(parse_error(scene),
            "scene.json: solver.integrator: unknown value \"rk5\" (expected symplectic_euler, "
            "rk4, implicit_euler)");
  scene = minimal_scene();
  scene["material"]["model"] = "linear";
  EXPECT_EQ(parse_error(scene),
            "scene.json: material.model: unknown value \"linear\" (expected stvk, corotated, "
            "neohookean)");
}

TEST(SceneParser, ExclusiveAlternatives) {
  json scene = minimal_scene();
  scene["mesh"]["file"] = "a.msh";
  EXPECT_EQ(parse_error(scene),
            "scene.json: mesh: must have exactly one of file, box, surface, level_set, implicit");
  scene = minimal_scene();
  scene["prescribed"] =
      json::parse(R"([{"region": {"sphere": {"center": [0,0,0], "radius": 1}}}])");
  EXPECT_EQ(parse_error(scene),
            "scene.json: prescribed.0: must have exactly one of displacement, rotation");
  scene = minimal_scene();
  scene["fixed"] = json::parse(R"([{}])");
  EXPECT_EQ(parse_error(scene), "scene.json: fixed.0: must have exactly one of box, plane, sphere");
  scene = minimal_scene();
  scene.erase("fixed");
  EXPECT_EQ(parse_error(scene),
            "scene.json: fixed: static mode needs at least one fixed or prescribed group");
}

TEST(SceneParser, MalformedJsonReportsLineAndColumn) {
  const cli_test::TempFolder folder;
  const std::filesystem::path file = folder.path() / "malformed_scene.json";
  {
    std::ofstream out(file);
    out << "{\n  \"mesh\": {\"box\": 1},\n  \"material\": {,}\n}\n";
  }
  try {
    read_json_file(file);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr(file.string() + ": line 3, column 16:"));
  }
  EXPECT_THROW(read_json_file(file), InputError);
}

}  // namespace
}  // namespace strata::app
