// Independent check of the writers with python meshio (skipped when it is not installed).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include "io_test_utils.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

const char* const kPython = "/usr/bin/python3";

/// Runs `/usr/bin/python3 -c script` and returns its stdout (the script must not contain ').
/// Warnings (meshio prints some to stdout) go before a final line of results: only that line is
/// returned, with its newline.
std::string run_python(const std::string& script) {
  const std::string command = std::string(kPython) + " -c '" + script + "' 2>/dev/null";
  std::string output;
  if (FILE* pipe = ::popen(command.c_str(), "r")) {
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), pipe))
      output += buffer;
    ::pclose(pipe);
  }
  const std::size_t last = output.find_last_of('\n', output.size() >= 2 ? output.size() - 2 : 0);
  return last == std::string::npos || last + 1 >= output.size() ? output : output.substr(last + 1);
}

bool meshio_available() {
  if (!fs::exists(kPython)) return false;
  return run_python("import meshio; print(\"ok\")") == "ok\n";
}

std::string meshio_counts(const fs::path& path) {
  return run_python("import meshio; m=meshio.read(\"" + path.string() +
                    "\"); print(len(m.points), sum(len(c.data) for c in m.cells if "
                    "c.type==\"tetra\"))");
}

TEST(IoMeshio, MeshioReadsOurVtuMeditAndGmsh) {
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  ScratchDir dir("io_meshio");
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 2, 3), {2, 3, 4});
  const std::string expected =
      std::to_string(mesh.vertices.rows()) + " " + std::to_string(mesh.tets.rows()) + "\n";
  for (const std::string name : {"box.vtu", "box.mesh", "box.msh"}) {
    SCOPED_TRACE(name);
    write_tet_mesh(dir / name, mesh);
    EXPECT_EQ(meshio_counts(dir / name), expected);
  }
  write_tet_mesh(dir / "box22.msh", mesh, {GmshVersion::v2_2});
  EXPECT_EQ(meshio_counts(dir / "box22.msh"), expected);
}

class IoMeshioEncoding : public ::testing::TestWithParam<VtkEncoding> {};

TEST_P(IoMeshioEncoding, MeshioSeesFrameFieldsWithTheirShapes) {
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  ScratchDir dir(GetParam() == VtkEncoding::binary ? "io_meshio_binary_fields"
                                                   : "io_meshio_ascii_fields");
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(1, 1, 1), {1, 2, 1});
  const Index nv = mesh.vertices.rows(), nt = mesh.tets.rows();
  VtuFields fields;
  fields.add_point_data("displacement", Eigen::MatrixXd::Constant(nv, 3, 0.25));
  fields.add_cell_data("stress", Eigen::MatrixXd::Ones(nt, 6));
  fields.add_cell_data("von_mises", Eigen::MatrixXd::Constant(nt, 1, 2.0));
  fields.add_cell_data("level", Eigen::MatrixXi::Constant(nt, 1, 3));
  write_vtu(dir / "frame.vtu", mesh.vertices, mesh.tets, fields, GetParam());
  const std::string output =
      run_python("import meshio; m=meshio.read(\"" + (dir / "frame.vtu").string() +
                 "\"); d=m.point_data[\"displacement\"]; s=m.cell_data[\"stress\"][0]; "
                 "v=m.cell_data[\"von_mises\"][0]; l=m.cell_data[\"level\"][0]; "
                 "print(d.shape, d.sum(), s.shape, v.sum(), l.dtype.kind, l.sum())");
  std::ostringstream expected;
  expected << "(" << nv << ", 3) " << nv * 3 / 4 << ".0 (" << nt << ", 6) " << 2 * nt << ".0 i "
           << 3 * nt << "\n";
  EXPECT_EQ(output, expected.str());
}

INSTANTIATE_TEST_SUITE_P(Encodings, IoMeshioEncoding,
                         ::testing::Values(VtkEncoding::binary, VtkEncoding::ascii),
                         [](const ::testing::TestParamInfo<VtkEncoding>& info) {
                           return info.param == VtkEncoding::binary ? "binary" : "ascii";
                         });

TEST(IoMeshio, MeshioReadsStoredAndDeflatedArraysOfABinaryFrameExactly) {
  // A field of noise is stored in zlib's uncompressed blocks, a smooth one deflated: an
  // independent reader gets the same doubles from the binary frame as from the ASCII one.
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  ScratchDir dir("io_meshio_stored");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {10, 10, 20});
  const Index nt = mesh.tets.rows();
  VtuFields fields;
  fields.add_cell_data("stress", 1e6 * Eigen::MatrixXd::Random(nt, 6));
  fields.add_point_data("displacement", 1e-3 * mesh.vertices);
  for (const auto encoding : {VtkEncoding::binary, VtkEncoding::ascii})
    write_vtu(dir / (encoding == VtkEncoding::binary ? "binary.vtu" : "ascii.vtu"), mesh.vertices,
              mesh.tets, fields, encoding);
  const std::string output =
      run_python("import meshio; b=meshio.read(\"" + (dir / "binary.vtu").string() +
                 "\"); a=meshio.read(\"" + (dir / "ascii.vtu").string() +
                 "\"); print((b.cell_data[\"stress\"][0]==a.cell_data[\"stress\"][0]).all(), "
                 "(b.point_data[\"displacement\"]==a.point_data[\"displacement\"]).all(), "
                 "b.cell_data[\"stress\"][0].shape)");
  EXPECT_EQ(output, "True True (" + std::to_string(nt) + ", 6)\n");
}

TEST(IoMeshio, ReadsMeshioBinaryVtu) {
  if (!meshio_available()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  ScratchDir dir("io_meshio_binary");
  TetMesh mesh = box_tet_mesh(Vector3d(-1, 0.1, 0.3), Vector3d(1, 0.7, 2.9), {2, 2, 3});
  mesh.vertices(1, 0) = 1.0 / 3.0;
  write_vtu(dir / "ascii.vtu", mesh, VtkEncoding::ascii);
  for (const std::string compression : {"None", "\"zlib\""}) {
    SCOPED_TRACE(compression);
    const std::string output =
        run_python("import meshio; m=meshio.read(\"" + (dir / "ascii.vtu").string() +
                   "\"); meshio.vtu.write(\"" + (dir / "binary.vtu").string() +
                   "\", m, binary=True, compression=" + compression + "); print(\"done\")");
    ASSERT_EQ(output, "done\n");
    const TetMesh back = read_tet_mesh(dir / "binary.vtu");
    ASSERT_EQ(back.vertices.rows(), mesh.vertices.rows());
    ASSERT_EQ(back.tets.rows(), mesh.tets.rows());
    EXPECT_TRUE((back.vertices.array() == mesh.vertices.array()).all());
    EXPECT_TRUE((back.tets.array() == mesh.tets.array()).all());
  }
}

}  // namespace
}  // namespace strata
