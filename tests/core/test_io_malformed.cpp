// Malformed mesh files: every failure is an InputError naming the file; nothing crashes or hangs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "io_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/core/io/tetgen.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

/// Reading `path` throws an InputError whose message names the file and contains `detail`.
void expect_input_error(const fs::path& path, const std::string& detail = "") {
  try {
    read_tet_mesh(path);
    ADD_FAILURE() << "no error reading " << path;
  } catch (const InputError& error) {
    const std::string message = error.what();
    // A TetGen pair may name the sibling that is broken: compare the stem there.
    const bool tetgen = path.extension() == ".node" || path.extension() == ".ele";
    const std::string name = tetgen ? path.stem().string() + "." : path.filename().string();
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find(detail), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one-line message: " << message;
  }
}

TEST(IoMalformed, MissingFileAndUnknownExtension) {
  ScratchDir dir("io_missing");
  for (const std::string name : {"none.msh", "none.mesh", "none.node", "none.ele", "none.vtu"})
    expect_input_error(dir / name);
  write_text(dir / "mesh.obj", "v 0 0 0\n");
  expect_input_error(dir / "mesh.obj", "unknown mesh extension");
  fs::create_directories(dir / "folder.msh");
  expect_input_error(dir / "folder.msh");
}

TEST(IoMalformed, EmptyAndGarbageFiles) {
  ScratchDir dir("io_garbage");
  for (const std::string name : {"e.msh", "e.mesh", "e.node", "e.vtu"}) {
    write_text(dir / name, "");
    expect_input_error(dir / name);
    write_text(dir / name, "hello world\nthis is not a mesh at all\n");
    expect_input_error(dir / name);
    write_text(dir / name, std::string("\x00\xff\x13<<>>\"\x01", 10));
    expect_input_error(dir / name);
  }
  write_text(dir / "e.ele", "hello");  // .node sibling is garbage too
  expect_input_error(dir / "e.ele");
}

TEST(IoMalformed, SpecificErrors) {
  ScratchDir dir("io_specific");
  write_text(dir / "binary.msh", "$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n");
  expect_input_error(dir / "binary.msh", "binary .msh not supported");
  write_text(dir / "v3.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
  expect_input_error(dir / "v3.msh", "unsupported .msh version");
  const std::string header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  const std::string nodes = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
  write_text(dir / "bad_tag.msh", header + nodes + "$Elements\n1\n1 4 0 1 2 3 9\n$EndElements\n");
  expect_input_error(dir / "bad_tag.msh", "node tag 9");
  write_text(dir / "no_tets.msh", header + nodes + "$Elements\n1\n1 2 0 1 2 3\n$EndElements\n");
  expect_input_error(dir / "no_tets.msh", "no tetrahedra");
  write_text(dir / "nan_token.msh", header + "$Nodes\n1\n1 0 zero 0\n$EndNodes\n");
  expect_input_error(dir / "nan_token.msh", "nan_token.msh:6: expected a number");
  write_text(dir / "huge.msh", header + "$Nodes\n999999999999\n1 0 0 0\n$EndNodes\n");
  expect_input_error(dir / "huge.msh", "larger than the rest of the file");
  write_text(dir / "open.msh", header + "$Comments\nsome words\n");
  expect_input_error(dir / "open.msh", "has no $EndComments");

  write_text(dir / "bad_index.mesh",
             "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
             "0 0 1 0\nTetrahedra\n1\n1 2 3 5 0\nEnd\n");
  expect_input_error(dir / "bad_index.mesh", "references vertex 5");
  write_text(dir / "zero_index.mesh",
             "Dimension 3\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n0 1 1 1 0\nEnd\n");
  expect_input_error(dir / "zero_index.mesh", "zero_index.mesh:7");
  write_text(dir / "flat.mesh", "Dimension 2\nVertices\n1\n0 0 0\nEnd\n");
  expect_input_error(dir / "flat.mesh", "only 3D");

  write_text(dir / "t.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  write_text(dir / "t.ele", "1 4 0\n1 1 2 3 5\n");
  expect_input_error(dir / "t.node", "t.ele:2");
  write_text(dir / "u.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  expect_input_error(dir / "u.node", "u.ele");  // sibling missing

  const std::string vtu_head =
      "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" "
      "NumberOfCells=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
      "format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Cells>";
  const std::string vtu_tail =
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray>"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece>"
      "</UnstructuredGrid></VTKFile>";
  write_text(dir / "ok.vtu", vtu_head +
                                 "<DataArray type=\"Int64\" Name=\"connectivity\" "
                                 "format=\"ascii\">0 1 2 3</DataArray>" +
                                 vtu_tail);
  EXPECT_EQ(read_tet_mesh(dir / "ok.vtu").tets.rows(), 1);
  write_text(dir / "index.vtu", vtu_head +
                                    "<DataArray type=\"Int64\" Name=\"connectivity\" "
                                    "format=\"ascii\">0 1 2 4</DataArray>" +
                                    vtu_tail);
  expect_input_error(dir / "index.vtu", "references point 4");
  write_text(dir / "word.vtu", vtu_head +
                                   "<DataArray type=\"Int64\" Name=\"connectivity\" "
                                   "format=\"ascii\">0 1 two 3</DataArray>" +
                                   vtu_tail);
  expect_input_error(dir / "word.vtu", "'two' is not a number");
  const std::string appended_head =
      "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" "
      "NumberOfCells=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
      "format=\"appended\" offset=\"";
  write_text(dir / "far.vtu", appended_head +
                                  "99\"/></Points></Piece></UnstructuredGrid>"
                                  "<AppendedData encoding=\"raw\">_xx</AppendedData></VTKFile>");
  expect_input_error(dir / "far.vtu", "starts past the end of the file");
  write_text(dir / "short.vtu", appended_head +
                                    "0\"/></Points></Piece></UnstructuredGrid>"
                                    "<AppendedData encoding=\"raw\">_xx</AppendedData></VTKFile>");
  expect_input_error(dir / "short.vtu", "which the data does not hold");
  write_text(dir / "b64.vtu",
             appended_head +
                 "0\"/></Points></Piece></UnstructuredGrid>"
                 "<AppendedData encoding=\"base64\">_AAAA</AppendedData></VTKFile>");
  expect_input_error(dir / "b64.vtu", "encoding 'base64' is not supported");
  write_text(dir / "no_block.vtu",
             appended_head + "0\"/></Points></Piece></UnstructuredGrid></VTKFile>");
  expect_input_error(dir / "no_block.vtu", "has no <AppendedData>");
  write_text(dir / "lzma.vtu",
             "<VTKFile type=\"UnstructuredGrid\" compressor=\"vtkLZMADataCompressor\"></VTKFile>");
  expect_input_error(dir / "lzma.vtu", "compressor 'vtkLZMADataCompressor' is not supported");
  write_text(dir / "poly.vtu", "<VTKFile type=\"PolyData\"></VTKFile>");
  expect_input_error(dir / "poly.vtu", "UnstructuredGrid");
}

/// Every prefix of a valid file, and copies with one byte changed, either read or throw
/// InputError naming the file: no crash, no hang, no other exception. Each variant goes to a new
/// file (truncating an existing file is slow on some file systems).
TEST(IoMalformed, TruncatedAndCorruptedFilesNeverCrash) {
  ScratchDir dir("io_truncated");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  write_tet_mesh(dir / "source.msh", mesh);
  write_tet_mesh(dir / "source22.msh", mesh, {GmshVersion::v2_2});
  write_tet_mesh(dir / "source.mesh", mesh);
  write_tet_mesh(dir / "source.vtu", mesh);  // binary: appended, zlib-compressed
  write_vtu(dir / "source_ascii.vtu", mesh, VtkEncoding::ascii);
  write_tet_mesh(dir / "source.node", mesh);
  struct Case {
    std::string source, extension, sibling_extension;
  };
  const Case cases[] = {{"source.msh", ".msh", ""},       {"source22.msh", ".msh", ""},
                        {"source.mesh", ".mesh", ""},     {"source.vtu", ".vtu", ""},
                        {"source_ascii.vtu", ".vtu", ""}, {"source.node", ".node", ".ele"},
                        {"source.ele", ".ele", ".node"}};
  std::mt19937 random(3);
  int counter = 0;
  for (const Case& test_case : cases) {
    SCOPED_TRACE(test_case.source);
    const std::string text = read_text(dir / test_case.source);
    const std::string sibling_text =
        test_case.sibling_extension.empty()
            ? ""
            : read_text((dir / test_case.source).replace_extension(test_case.sibling_extension));
    int failures = 0, successes = 0;
    auto try_read = [&](const std::string& variant) {
      const std::string stem = std::string("v").append(std::to_string(counter++));
      const fs::path target = dir / (stem + test_case.extension);
      write_text(target, variant);
      if (!test_case.sibling_extension.empty())
        write_text(dir / (stem + test_case.sibling_extension), sibling_text);
      try {
        const TetMesh result = read_tet_mesh(target);
        ++successes;
        EXPECT_GT(result.tets.rows(), 0);
      } catch (const InputError& error) {
        ++failures;
        ASSERT_NE(std::string(error.what()).find(stem + "."), std::string::npos) << error.what();
      }
    };
    for (std::size_t length = 0; length < text.size(); ++length)
      try_read(text.substr(0, length));
    EXPECT_GT(failures, static_cast<int>(text.size()) / 2);
    std::uniform_int_distribution<std::size_t> position(0, text.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int trial = 0; trial < 200; ++trial) {
      std::string corrupted = text;
      corrupted[position(random)] = static_cast<char>(byte(random));
      try_read(corrupted);
    }
    EXPECT_GT(successes, 0);
  }
}

}  // namespace
}  // namespace strata
