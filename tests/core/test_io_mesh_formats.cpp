// Round trips of every tet mesh format and hand-written fixture files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "io_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/gmsh.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/core/io/tetgen.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

/// A fresh folder under the system temp folder, removed at the end of the test.
/// A box mesh with irregular coordinates, so the round trip exercises all 17 digits.
TetMesh irregular_box() {
  TetMesh mesh =
      box_tet_mesh(Vector3d(-0.3, 0.1, 1.0 / 3.0), Vector3d(1.7, 2.0 / 7.0, 2.5), {3, 2, 4});
  std::mt19937 random(7);
  std::uniform_real_distribution<double> noise(-1e-3, 1e-3);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    for (int d = 0; d < 3; ++d)
      mesh.vertices(v, d) += noise(random) * std::pow(10.0, d - 1);
  return mesh;
}

void expect_same_mesh(const TetMesh& expected, const TetMesh& actual) {
  ASSERT_EQ(expected.tets.rows(), actual.tets.rows());
  ASSERT_EQ(expected.vertices.rows(), actual.vertices.rows());
  EXPECT_TRUE((expected.tets.array() == actual.tets.array()).all());
  // Shortest round-trip formatting gives back every double exactly; the brief asks 1e-15 relative.
  const double scale = expected.vertices.cwiseAbs().maxCoeff();
  EXPECT_LE((expected.vertices - actual.vertices).cwiseAbs().maxCoeff(), 1e-15 * scale);
  EXPECT_TRUE((expected.vertices.array() == actual.vertices.array()).all());
}

TEST(IoMeshFormats, RoundTripEveryFormat) {
  ScratchDir dir("io_round_trip");
  const TetMesh mesh = irregular_box();
  for (const std::string name : {"box.msh", "box.mesh", "box.node", "box.vtu", "BOX.MSH"}) {
    SCOPED_TRACE(name);
    write_tet_mesh(dir / name, mesh);
    expect_same_mesh(mesh, read_tet_mesh(dir / name));
  }
  // TetGen: the .ele path finds the .node sibling written with it.
  expect_same_mesh(mesh, read_tet_mesh(dir / "box.ele"));
}

TEST(IoMeshFormats, GmshVersion22RoundTrip) {
  ScratchDir dir("io_gmsh22");
  const TetMesh mesh = irregular_box();
  write_tet_mesh(dir / "box.msh", mesh, {GmshVersion::v2_2});
  expect_same_mesh(mesh, read_gmsh(dir / "box.msh"));
}

TEST(IoMeshFormats, ConvertChainKeepsMesh) {
  ScratchDir dir("io_convert");
  const TetMesh mesh = irregular_box();
  write_tet_mesh(dir / "a.vtu", mesh);
  convert_tet_mesh(dir / "a.vtu", dir / "b.msh");
  convert_tet_mesh(dir / "b.msh", dir / "c.mesh");
  convert_tet_mesh(dir / "c.mesh", dir / "d.ele");
  convert_tet_mesh(dir / "d.node", dir / "e.vtu");
  expect_same_mesh(mesh, read_tet_mesh(dir / "e.vtu"));
}

/// The fixtures are a 2 × 1 × 0.5 box with corners numbered 0..7 (x fastest, then y, then z)
/// and the same five tets.
void expect_cube5(const TetMesh& mesh) {
  ASSERT_EQ(mesh.vertices.rows(), 8);
  ASSERT_EQ(mesh.tets.rows(), 5);
  const double corners[8][3] = {{0, 0, 0},   {2, 0, 0},   {2, 1, 0},   {0, 1, 0},
                                {0, 0, 0.5}, {2, 0, 0.5}, {2, 1, 0.5}, {0, 1, 0.5}};
  for (int v = 0; v < 8; ++v)
    for (int d = 0; d < 3; ++d)
      EXPECT_EQ(mesh.vertices(v, d), corners[v][d]) << v << " " << d;
  const int tets[5][4] = {{0, 1, 3, 4}, {2, 3, 1, 6}, {5, 4, 6, 1}, {7, 6, 4, 3}, {1, 3, 4, 6}};
  for (int t = 0; t < 5; ++t)
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(mesh.tets(t, k), tets[t][k]) << t << " " << k;
  TetMesh checked = mesh;
  EXPECT_NO_THROW(validate_tet_mesh(checked, "fixture"));
  EXPECT_EQ(orient_tets(checked), 0);
  EXPECT_NEAR(mesh_volume(checked), 1.0, 1e-15);
}

const fs::path kData = STRATA_TEST_DATA_DIR;

TEST(IoMeshFormats, GmshV22FixtureWithSparseTagsAndOtherElements) {
  expect_cube5(read_tet_mesh(kData / "cube5_v22.msh"));
}

TEST(IoMeshFormats, GmshV41FixtureWithBlocksEntitiesAndParametricNodes) {
  expect_cube5(read_tet_mesh(kData / "cube5_v41.msh"));
}

TEST(IoMeshFormats, MeditFixtureWithMixedCaseKeywordsAndSkippedSections) {
  expect_cube5(read_tet_mesh(kData / "cube5.mesh"));
}

TEST(IoMeshFormats, TetgenFixtureOneBasedWithAttributesAndMarkers) {
  expect_cube5(read_tet_mesh(kData / "cube5.node"));
  expect_cube5(read_tet_mesh(kData / "cube5.ele"));
}

TEST(IoMeshFormats, TetgenZeroBasedNumbering) {
  ScratchDir dir("io_tetgen0");
  {
    std::ofstream(dir / "m.node") << "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    std::ofstream(dir / "m.ele") << "1 4 0\n0 0 1 2 3\n";
  }
  const TetMesh mesh = read_tet_mesh(dir / "m.ele");
  ASSERT_EQ(mesh.tets.rows(), 1);
  EXPECT_EQ(mesh.tets(0, 3), 3);
  EXPECT_EQ(mesh.vertices(3, 2), 1.0);
}

TEST(IoMeshFormats, FormatFromExtension) {
  EXPECT_EQ(mesh_format_of("a/b.MSH"), MeshFormat::gmsh);
  EXPECT_EQ(mesh_format_of("b.mesh"), MeshFormat::medit);
  EXPECT_EQ(mesh_format_of("b.ele"), MeshFormat::tetgen);
  EXPECT_EQ(mesh_format_of("b.vtu"), MeshFormat::vtu);
  EXPECT_THROW(mesh_format_of("b.obj"), InputError);
  EXPECT_THROW(mesh_format_of("b"), InputError);
}

}  // namespace
}  // namespace strata
