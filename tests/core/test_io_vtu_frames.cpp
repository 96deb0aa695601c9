// VTU frames with fields and ParaView .pvd series.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/io/pvd.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

TEST(IoVtuFrames, FrameWithFieldsReadsBackDeformedPositions) {
  ScratchDir dir("io_frame");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 1, 1});
  MatrixX3d displacement = MatrixX3d::Zero(mesh.vertices.rows(), 3);
  displacement.col(2) = 0.1 * mesh.vertices.col(0);
  const MatrixX3d positions = mesh.vertices + displacement;
  VtuFields fields;
  fields.add_point_data("displacement", displacement);
  fields.add_cell_data("green_strain", Eigen::MatrixXd::Random(mesh.tets.rows(), 6));
  fields.add_cell_data("level", Eigen::MatrixXi::Zero(mesh.tets.rows(), 1));
  fields.add_point_data("a<b&\"c\"", Eigen::MatrixXd::Zero(mesh.vertices.rows(), 1));
  write_vtu(dir / "f.vtu", positions, mesh.tets, fields);

  const TetMesh back = read_vtu(dir / "f.vtu");
  EXPECT_TRUE((back.vertices.array() == positions.array()).all());
  EXPECT_TRUE((back.tets.array() == mesh.tets.array()).all());
  const std::string text = read_text(dir / "f.vtu");
  EXPECT_EQ(count(text, "Name=\"displacement\" NumberOfComponents=\"3\""), 1);
  EXPECT_EQ(count(text, "type=\"Float64\" Name=\"green_strain\" NumberOfComponents=\"6\""), 1);
  EXPECT_EQ(count(text, "type=\"Int32\" Name=\"level\" NumberOfComponents=\"1\""), 1);
  EXPECT_EQ(count(text, "Name=\"a&lt;b&amp;&quot;c&quot;\""), 1);
}

TEST(IoVtuFrames, BothEncodingsReadBackTheIdenticalArrays) {
  ScratchDir dir("io_frame_encodings");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {6, 5, 4});
  const Index nv = mesh.vertices.rows(), nt = mesh.tets.rows();
  const MatrixX3d positions = mesh.vertices + 1e-3 * MatrixX3d::Random(nv, 3);
  VtuFields fields;
  const Eigen::MatrixXd velocity = Eigen::MatrixXd::Random(nv, 3);
  const Eigen::MatrixXd stress = 1e6 * Eigen::MatrixXd::Random(nt, 6);
  const Eigen::MatrixXi level = Eigen::VectorXi::LinSpaced(nt, -3, 7);
  fields.add_point_data("velocity", velocity);
  fields.add_cell_data("stress", stress);
  fields.add_cell_data("level", level);
  write_vtu(dir / "binary.vtu", positions, mesh.tets, fields, VtkEncoding::binary);
  write_vtu(dir / "ascii.vtu", positions, mesh.tets, fields, VtkEncoding::ascii);
  for (const char* name : {"binary.vtu", "ascii.vtu"}) {
    SCOPED_TRACE(name);
    const VtkFrame frame = read_vtk_frame(dir / name);
    EXPECT_EQ(frame.type, "UnstructuredGrid");
    EXPECT_TRUE((frame.points.array() == positions.array()).all());
    EXPECT_TRUE((frame.point_field("velocity").array() == velocity.array()).all());
    EXPECT_TRUE((frame.cell_field("stress").array() == stress.array()).all());
    EXPECT_TRUE((frame.cell_field("level").cast<int>().array() == level.array()).all());
    ASSERT_EQ(frame.cells.size(), 3u);
    EXPECT_EQ(frame.cells[0].first, "Cells/connectivity");
    EXPECT_EQ(frame.cells[0].second.size(), static_cast<std::size_t>(4 * nt));
    EXPECT_EQ(frame.cells[0].second[5], mesh.tets(1, 1));
    EXPECT_THROW(frame.point_field("missing"), InputError);
    const TetMesh back = read_vtu(dir / name);
    EXPECT_TRUE((back.tets.array() == mesh.tets.array()).all());
  }
  EXPECT_THAT(read_text(dir / "binary.vtu"), ::testing::HasSubstr("vtkZLibDataCompressor"));
  EXPECT_LT(fs::file_size(dir / "binary.vtu"), fs::file_size(dir / "ascii.vtu") / 2);
}

TEST(IoVtuFrames, ArraysOfManyCompressedBlocksReadBackAndDoNotDependOnTheThreads) {
  // 12,000 tets: the stress array is 576,000 bytes, nine zlib blocks of 64 KiB (noise: stored
  // after its first), and a smooth strain of as many blocks, deflated in parallel; both appended
  // in order.
  if (max_threads() < 2) GTEST_SKIP() << "one thread: nothing to compare";
  ScratchDir dir("io_frame_blocks");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {10, 10, 20});
  const Index nt = mesh.tets.rows();
  ASSERT_GT(6 * nt * static_cast<Index>(sizeof(double)), 8 * 65536);
  VtuFields fields;
  const Eigen::MatrixXd stress = 1e6 * Eigen::MatrixXd::Random(nt, 6);
  Eigen::MatrixXd strain(nt, 6);
  for (Index t = 0; t < nt; ++t)
    strain.row(t).setConstant(1e-3 * static_cast<double>(t / 16));
  fields.add_cell_data("stress", stress);
  fields.add_cell_data("green_strain", strain);
  write_vtu(dir / "threads.vtu", mesh.vertices, mesh.tets, fields, VtkEncoding::binary);
  {
    const ThreadLimit serial(1);
    write_vtu(dir / "serial.vtu", mesh.vertices, mesh.tets, fields, VtkEncoding::binary);
  }
  EXPECT_EQ(read_text(dir / "threads.vtu"), read_text(dir / "serial.vtu"));
  const VtkFrame frame = read_vtk_frame(dir / "threads.vtu");
  EXPECT_TRUE((frame.cell_field("stress").array() == stress.array()).all());
  EXPECT_TRUE((frame.cell_field("green_strain").array() == strain.array()).all());
  EXPECT_TRUE((frame.points.array() == mesh.vertices.array()).all());
}

/// The deflate block types (0 stored, 1 fixed, 2 dynamic Huffman) that begin the zlib blocks of
/// the appended array `name` in a binary .vtu.
std::vector<int> deflate_block_types(const std::string& text, const std::string& name) {
  const std::size_t tag = text.find("Name=\"" + name + "\"");
  const std::size_t offset_at = text.find("offset=\"", tag) + 8;
  const std::size_t offset = std::stoull(text.substr(offset_at, text.find('"', offset_at)));
  const std::size_t data = text.find('_', text.find("<AppendedData")) + 1 + offset;
  const auto word = [&](std::size_t i) {
    std::uint64_t value = 0;
    std::memcpy(&value, text.data() + data + 8 * i, sizeof value);
    return static_cast<std::size_t>(value);
  };
  std::vector<int> types;
  std::size_t at = data + 8 * (3 + word(0));
  for (std::size_t b = 0; b < word(0); ++b) {
    // Two bytes of zlib header, then the first deflate block's header: BFINAL, then BTYPE.
    types.push_back((static_cast<unsigned char>(text[at + 2]) >> 1) & 3);
    at += word(3 + b);
  }
  return types;
}

TEST(IoVtuFrames, ArraysThatDoNotDeflateAreStoredAndReadBackExactly) {
  ScratchDir dir("io_frame_stored");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {10, 10, 20});
  const Index nt = mesh.tets.rows();
  VtuFields fields;
  const Eigen::MatrixXd stress = 1e6 * Eigen::MatrixXd::Random(nt, 6);  // nine blocks of noise
  Eigen::MatrixXd strain = Eigen::MatrixXd::Zero(nt, 6);
  strain.col(2).setConstant(1e-3);
  strain.bottomRows(nt / 2) = 1e-3 * Eigen::MatrixXd::Random(nt / 2, 6);  // noise after zeros
  fields.add_cell_data("stress", stress);
  fields.add_cell_data("green_strain", strain);
  write_vtu(dir / "f.vtu", mesh.vertices, mesh.tets, fields, VtkEncoding::binary);
  const std::string text = read_text(dir / "f.vtu");
  // The noise is stored after its first block (which decides, and is kept deflated); the strain,
  // whose first block deflates, is deflated throughout (its noisy half too), as is the
  // connectivity.
  const std::vector<int> stress_types = deflate_block_types(text, "stress");
  ASSERT_EQ(stress_types.size(), 9u);
  EXPECT_THAT(std::vector<int>(stress_types.begin() + 1, stress_types.end()), ::testing::Each(0));
  EXPECT_THAT(deflate_block_types(text, "green_strain"), ::testing::Each(::testing::Gt(0)));
  EXPECT_THAT(deflate_block_types(text, "connectivity"), ::testing::Each(::testing::Gt(0)));
  const VtkFrame frame = read_vtk_frame(dir / "f.vtu");
  EXPECT_TRUE((frame.cell_field("stress").array() == stress.array()).all());
  EXPECT_TRUE((frame.cell_field("green_strain").array() == strain.array()).all());
}

TEST(IoVtuFrames, ACacheReusesRepeatedIntegerArraysAndWritesTheSameBytes) {
  // Frames of a series: the cache must give the bytes written without it, reuse an integer array
  // only when its bytes repeat, and never hold a float array.
  ScratchDir dir("io_frame_cache");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {12, 12, 12});  // 10k tets
  TetMesh permuted = mesh;  // the same tets in another order: same offsets and types
  permuted.tets.topRows(100).swap(permuted.tets.bottomRows(100));
  const TetMesh smaller = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {12, 12, 11});
  struct Frame {
    const TetMesh* mesh;
    double scale;
    int level;
  };
  // Positions change every frame; the mesh and the levels only at frames 2, 3 and 4.
  const std::vector<Frame> frames = {{&mesh, 0.1, 0},
                                     {&mesh, 0.2, 0},
                                     {&permuted, 0.3, 0},
                                     {&permuted, 0.4, 1},
                                     {&smaller, 0.5, 1}};
  // Arrays compressed (not taken from the cache) at each frame: connectivity, offsets, types,
  // level.
  const std::vector<std::size_t> compressed_after = {4, 4, 5, 6, 10};
  VtuArrayCache cache;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const TetMesh& m = *frames[f].mesh;
    MatrixX3d displacement = MatrixX3d::Zero(m.vertices.rows(), 3);
    displacement.col(2) = frames[f].scale * m.vertices.col(0).array().square().matrix();
    VtuFields fields;
    fields.add_point_data("displacement", displacement);
    fields.add_cell_data("stress", Eigen::MatrixXd::Constant(m.tets.rows(), 6, frames[f].scale));
    fields.add_cell_data("level", Eigen::MatrixXi::Constant(m.tets.rows(), 1, frames[f].level));
    const MatrixX3d positions = m.vertices + displacement;
    write_vtu(dir / "plain.vtu", positions, m.tets, fields);
    write_vtu(dir / "cached.vtu", positions, m.tets, fields, VtkEncoding::binary, &cache);
    EXPECT_EQ(read_text(dir / "cached.vtu"), read_text(dir / "plain.vtu")) << "frame " << f;
    EXPECT_EQ(cache.compressed(), compressed_after[f]) << "frame " << f;
    EXPECT_EQ(cache.reused() + cache.compressed(), 4 * (f + 1)) << "frame " << f;
  }
  // ASCII frames do not use it.
  write_vtu(dir / "a.vtu", mesh.vertices, mesh.tets, {}, VtkEncoding::ascii, &cache);
  EXPECT_EQ(cache.reused() + cache.compressed(), 4 * frames.size());
}

TEST(IoVtuFrames, FieldWithWrongRowCountIsInputErrorNamingIt) {
  ScratchDir dir("io_frame_rows");
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  VtuFields fields;
  fields.add_point_data("velocity", Eigen::MatrixXd::Zero(mesh.vertices.rows() + 1, 3));
  try {
    write_vtu(dir / "f.vtu", mesh.vertices, mesh.tets, fields);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("velocity"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("f.vtu"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir / "f.vtu"));
}

TEST(IoVtuFrames, PvdIsValidAfterEveryFrame) {
  ScratchDir dir("io_pvd");
  const fs::path pvd = dir / "run.pvd";
  PvdWriter writer(pvd);
  std::string text = read_text(pvd);
  EXPECT_EQ(count(text, "<DataSet"), 0);
  EXPECT_EQ(count(text, "</VTKFile>"), 1);
  for (int frame = 0; frame < 3; ++frame) {
    writer.add_frame(0.5 * frame, "frames/frame_" + std::to_string(frame) + ".vtu");
    text = read_text(pvd);
    EXPECT_EQ(count(text, "<DataSet"), frame + 1);
    EXPECT_EQ(count(text, "</VTKFile>"), 1);
    EXPECT_EQ(count(text, "file=\"frames/frame_" + std::to_string(frame) + ".vtu\""), 1);
  }
  writer.add_frame(1.0, "frames/surface_2.vtp", 1);
  text = read_text(pvd);
  EXPECT_EQ(count(text, "timestep=\"1\" group=\"\" part=\"1\" file=\"frames/surface_2.vtp\""), 1);
  EXPECT_EQ(count(text, "timestep=\"0.5\" group=\"\" part=\"0\""), 1);
  EXPECT_EQ(writer.entries().size(), 4u);
}

TEST(IoVtuFrames, PvdInMissingFolderIsInputError) {
  ScratchDir dir("io_pvd_missing");
  EXPECT_THROW(PvdWriter(dir / "nope" / "run.pvd"), InputError);
}

}  // namespace
}  // namespace strata
