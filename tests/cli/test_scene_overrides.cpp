// --set overrides: parsing, paths with array indices, and errors naming the path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cli_test_utils.hpp"
#include "strata/app/scene_overrides.hpp"
#include "strata/app/scene_parser.hpp"

namespace strata::app {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

TEST(SceneOverrides, ValuesParseAsJsonElseString) {
  EXPECT_EQ(parse_override("solver.dt=1e-4").value, json(1e-4));
  EXPECT_EQ(parse_override("gravity=[0,0,-9.81]").value, json::parse("[0,0,-9.81]"));
  EXPECT_EQ(parse_override("solver.mode=static").value, json("static"));
  EXPECT_EQ(parse_override("output.vtk=false").value, json(false));
  EXPECT_EQ(parse_override("mesh.file=a=b.msh").value, json("a=b.msh"));
  EXPECT_EQ(parse_override("mesh.file=a=b.msh").path, "mesh.file");
  EXPECT_THROW(parse_override("solver.dt"), InputError);
  EXPECT_THROW(parse_override("=3"), InputError);
  EXPECT_THROW(parse_override("solver..dt=3"), InputError);
}

TEST(SceneOverrides, SetsNestedKeysAndArrayElements) {
  json root = json::parse(R"({"fixed": [{"box": {"min": [0,0,0], "max": [1,1,1]}}],
                               "solver": {"mode": "static"}})");
  apply_override(root, parse_override("fixed.0.box.min=[0,0,-1]"));
  EXPECT_EQ(root["fixed"][0]["box"]["min"], json::parse("[0,0,-1]"));
  apply_override(root, parse_override("fixed.0.box.max.2=5"));
  EXPECT_EQ(root["fixed"][0]["box"]["max"], json::parse("[1,1,5]"));
  apply_override(root, parse_override("solver.load_steps=4"));
  EXPECT_EQ(root["solver"]["load_steps"], json(4));
  apply_override(root, parse_override("output.every=3"));
  EXPECT_EQ(root["output"]["every"], json(3));
  apply_override(root,
                 parse_override("fixed.1={\"sphere\": {\"center\": [0,0,0], \"radius\": 1}}"));
  EXPECT_EQ(root["fixed"].size(), 2u);
}

TEST(SceneOverrides, BadPathsNameThePath) {
  json root = json::parse(R"({"fixed": [{"box": {}}], "solver": {"mode": "static"}})");
  try {
    apply_override(root, parse_override("fixed.3.box.min=[0,0,0]"));
    FAIL();
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("--set fixed.3.box.min: index 3 out of range"));
  }
  try {
    apply_override(root, parse_override("fixed.first=1"));
    FAIL();
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("--set fixed.first:"));
  }
  try {
    apply_override(root, parse_override("solver.mode.x=1"));
    FAIL();
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("--set solver.mode.x: solver.mode is not an object"));
  }
}

class SceneOverridesOnFile : public ::testing::Test {
 protected:
  void SetUp() override {
    m_file = m_folder.path() / "scene.json";
    std::ofstream out(m_file);
    out << R"({
      "mesh": {"box": {"min": [0, 0, 0], "max": [1, 0.1, 0.1], "cells": [4, 1, 1]}},
      "material": {"model": "stvk", "youngs_modulus": 1e6, "poisson_ratio": 0.3, "density": 1000},
      "fixed": [{"box": {"min": [0, 0, 0], "max": [0, 0.1, 0.1]}}],
      "solver": {"mode": "static"}
    })";
  }
  cli_test::TempFolder m_folder;  // per test and process: ctest runs tests in parallel
  std::filesystem::path m_file;
};

TEST_F(SceneOverridesOnFile, OverridesReachTheScene) {
  const Scene scene = load_scene(
      m_file, {"material.youngs_modulus=2e7", "fixed.0.box.max=[0,1,1]", "solver.mode=dynamic",
               "solver.dt=1e-3", "solver.duration=0.1", "gravity=[0,0,-9.81]"});
  EXPECT_DOUBLE_EQ(scene.material.youngs_modulus, 2e7);
  EXPECT_EQ(std::get<BoxRegion>(scene.fixed[0].region).max, Vector3d(0, 1, 1));
  EXPECT_EQ(scene.solver.mode, SimulationMode::dynamic);
  EXPECT_DOUBLE_EQ(scene.solver.dt, 1e-3);
  EXPECT_EQ(scene.gravity, Vector3d(0, 0, -9.81));
}

TEST_F(SceneOverridesOnFile, UnknownOverridePathIsNamed) {
  try {
    load_scene(m_file, {"material.young=5"});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "--set material.young: unknown key material.young");
  }
  try {
    load_scene(m_file, {"solverr.dt.x=5"});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "--set solverr.dt.x: unknown key solverr");
  }
  try {
    load_scene(m_file, {"material.poisson_ratio=0.7"});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("material.poisson_ratio: must be in [0, 0.5)"));
  }
}

}  // namespace
}  // namespace strata::app
