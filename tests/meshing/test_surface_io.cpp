// Surface readers (OFF, OBJ, PLY, STL): the same unit cube from every format, fan triangulation of
// quads, degenerate-triangle removal, and one-line errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/surface_mesh.hpp"

namespace strata {
namespace {

/// A fresh scratch folder per test.
class SurfaceIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_folder = std::filesystem::temp_directory_path() /
               ("strata_surface_io_" + std::string(info->name()) + "_" +
                std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    std::filesystem::remove_all(m_folder);
    std::filesystem::create_directories(m_folder);
  }
  void TearDown() override { std::filesystem::remove_all(m_folder); }

  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = m_folder / name;
    std::ofstream(path) << text;
    return path;
  }

  std::filesystem::path m_folder;
};

/// The cube [0, 1]³ as 6 outward quads (counter-clockwise seen from outside).
const char* const kCubeVertices = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n";
const int kCubeQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                              {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

std::string cube_off() {
  std::string text = std::string("OFF\n8 6 0\n") + kCubeVertices;
  for (const auto& q : kCubeQuads) {
    text += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
            " " + std::to_string(q[3]) + "\n";
  }
  return text;
}

std::string cube_obj() {
  std::string text;
  std::string vertices = kCubeVertices;
  std::size_t start = 0;
  for (std::size_t end; (end = vertices.find('\n', start)) != std::string::npos; start = end + 1) {
    text += "v " + vertices.substr(start, end - start) + "\n";
  }
  for (const auto& q : kCubeQuads) {  // OBJ indices start at 1
    text += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " +
            std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
  }
  return text;
}

std::string cube_ply() {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  text += kCubeVertices;
  for (const auto& q : kCubeQuads) {
    text += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
            " " + std::to_string(q[3]) + "\n";
  }
  return text;
}

/// ASCII STL: every triangle repeats its corners; the reader merges equal points.
std::string cube_stl() {
  const double x[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                          {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  std::string text = "solid cube\n";
  auto vertex = [&](int v) {
    return "vertex " + std::to_string(x[v][0]) + " " + std::to_string(x[v][1]) + " " +
           std::to_string(x[v][2]) + "\n";
  };
  for (const auto& q : kCubeQuads) {
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}) {
      text += "facet normal 0 0 0\nouter loop\n" + vertex(t[0]) + vertex(t[1]) + vertex(t[2]) +
              "endloop\nendfacet\n";
    }
  }
  return text + "endsolid cube\n";
}

void expect_unit_cube(const SurfaceMesh& surface) {
  EXPECT_EQ(surface.vertices.rows(), 8);
  EXPECT_EQ(surface.triangles.rows(), 12);
  EXPECT_NEAR(enclosed_volume(surface), 1.0, 1e-12);
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    EXPECT_FALSE(is_degenerate_triangle(surface, f)) << "triangle " << f;
  }
}

TEST_F(SurfaceIo, SameCubeFromEveryFormat) {
  expect_unit_cube(read_surface(write("cube.off", cube_off())));
  expect_unit_cube(read_surface(write("cube.obj", cube_obj())));
  expect_unit_cube(read_surface(write("cube.ply", cube_ply())));
  expect_unit_cube(read_surface(write("cube.stl", cube_stl())));
  expect_unit_cube(read_surface(write("CUBE.OFF", cube_off())));  // extension in any case
}

TEST_F(SurfaceIo, QuadsSplitIntoFansKeepOrientation) {
  const SurfaceMesh surface = read_surface(write("cube.off", cube_off()));
  // Quad (a, b, c, d) → (a, b, c), (a, c, d): both with the quad's normal.
  EXPECT_EQ(surface.triangles.row(0), Eigen::Vector3i(0, 2, 3).transpose());
  EXPECT_EQ(surface.triangles.row(1), Eigen::Vector3i(0, 3, 1).transpose());
}

TEST_F(SurfaceIo, RemovesDegenerateTrianglesAndTheirVertices) {
  std::string text = cube_off();
  text.replace(text.find("8 6 0"), 5, "10 8 0");
  text.insert(text.find("4 0 2 3 1"), "5 5 5\n6 6 6\n");
  text += "3 8 8 9\n3 0 1 8\n";  // a repeated corner; then a proper triangle far away
  text += "";
  SurfaceMesh surface = read_surface(write("extra.off", text));
  ASSERT_EQ(surface.triangles.rows(), 14);
  EXPECT_TRUE(is_degenerate_triangle(surface, 12));
  EXPECT_FALSE(is_degenerate_triangle(surface, 13));
  EXPECT_EQ(remove_degenerate_triangles(surface), 1);
  EXPECT_EQ(surface.triangles.rows(), 13);
  EXPECT_EQ(surface.vertices.rows(), 9);  // vertex 9 (6, 6, 6) was used only by the removed one
  EXPECT_EQ(surface.vertices.row(8), Vector3d(5, 5, 5).transpose());
}

TEST_F(SurfaceIo, CollinearTriangleIsDegenerate) {
  SurfaceMesh surface;
  surface.vertices.resize(3, 3);
  surface.vertices << 0, 0, 0, 1, 1, 1, 3, 3, 3;
  surface.triangles.resize(1, 3);
  surface.triangles << 0, 1, 2;
  EXPECT_TRUE(is_degenerate_triangle(surface, 0));
  surface.vertices(2, 0) += 1e-6;
  EXPECT_FALSE(is_degenerate_triangle(surface, 0));
}

/// The message of the InputError read_surface throws ("" if none).
std::string read_error(const std::filesystem::path& path) {
  try {
    read_surface(path);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST_F(SurfaceIo, BadInputGivesOneLineNamingTheFile) {
  const std::filesystem::path missing = m_folder / "missing.off";
  EXPECT_EQ(read_error(missing), missing.string() + ": no such file");
  const std::filesystem::path xyz = write("points.xyz", "0 0 0\n");
  EXPECT_EQ(read_error(xyz),
            xyz.string() + ": unknown surface format \".xyz\" (expected .off, .obj, .ply or .stl)");
  const std::filesystem::path empty = write("empty.off", "OFF\n0 0 0\n");
  EXPECT_EQ(read_error(empty), empty.string() + ": the surface has no triangles");
  const std::filesystem::path flat =
      write("flat.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n3 0 1 2\n3 1 2 3\n");
  EXPECT_EQ(read_error(flat), flat.string() + ": all 2 triangles are degenerate (zero area)");
  const std::filesystem::path range =
      write("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_NE(read_error(range).find(range.string() + ": "), std::string::npos);
  const std::filesystem::path garbage = write("garbage.ply", "this is not a ply file\n");
  EXPECT_EQ(read_error(garbage), garbage.string() + ": cannot parse as ply (malformed file)");
  for (const std::filesystem::path& path : {missing, xyz, empty, flat, range, garbage}) {
    EXPECT_EQ(read_error(path).find('\n'), std::string::npos) << path;
  }
}

TEST(SurfaceIoModels, ReadsTheCgalModels) {
  const std::filesystem::path models = STRATA_MODELS_DIR;
  if (!std::filesystem::exists(models / "armadillo.off")) {
    GTEST_SKIP() << "CGAL models not found in " << models << " (install libcgal-demo, reconfigure)";
  }
  const SurfaceMesh armadillo = read_surface(models / "armadillo.off");
  EXPECT_EQ(armadillo.vertices.rows(), 26002);
  EXPECT_EQ(armadillo.triangles.rows(), 52000);
  // The sphere in PLY and binary STL: the same closed surface, volume a bit under 4π/3 r³.
  const SurfaceMesh sphere_ply = read_surface(models / "sphere.ply");
  const SurfaceMesh sphere_stl = read_surface(models / "sphere.stl");
  EXPECT_EQ(sphere_ply.triangles.rows(), sphere_stl.triangles.rows());
  EXPECT_EQ(sphere_ply.vertices.rows(), sphere_stl.vertices.rows());
  EXPECT_NEAR(enclosed_volume(sphere_ply), enclosed_volume(sphere_stl),
              1e-6 * std::abs(enclosed_volume(sphere_ply)));
}

}  // namespace
}  // namespace strata
