// A Simulation built on a malformed mesh: one InputError naming the tet or vertex, never an
// access out of range.
#include <gtest/gtest.h>

#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// The message of the InputError that building a dynamic Simulation on `mesh` throws ("" if none).
std::string construction_error(const TetMesh& mesh) {
  Material material;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  SolverSettings settings;
  settings.mode = SimulationMode::dynamic;
  try {
    const Simulation sim(mesh, {.material = material, .gravity = Vector3d(0, 0, -9.81)}, settings);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SimMalformedMesh, TetIndicesOutOfRangeAndUnusedVerticesAreNamed) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {3, 3, 3});
  ASSERT_EQ(construction_error(mesh), "");
  const std::string vertices = std::to_string(mesh.vertices.rows());
  TetMesh beyond = mesh;
  beyond.tets(17, 3) = 1 << 30;
  EXPECT_EQ(construction_error(beyond), "mesh: tet 17 references vertex " +
                                            std::to_string(1 << 30) + " (mesh has " + vertices +
                                            " vertices)");
  TetMesh negative = mesh;
  negative.tets(5, 1) = -1;
  EXPECT_EQ(construction_error(negative),
            "mesh: tet 5 references vertex -1 (mesh has " + vertices + " vertices)");
  TetMesh unused = mesh;
  unused.vertices.conservativeResize(mesh.vertices.rows() + 1, 3);
  unused.vertices.row(mesh.vertices.rows()) = Vector3d(2, 2, 2).transpose();
  EXPECT_EQ(construction_error(unused), "mesh: vertex " + vertices + " belongs to no tet");
}

}  // namespace
}  // namespace strata
