// Atomic file writing: a failed write leaves the previous file intact and no temporary behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "io_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/mesh_io.hpp"
#include "strata/core/io/vtu.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::ScratchDir;
using testing::write_text;

int count_files(const fs::path& folder) {
  int count = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder))
    ++count;
  return count;
}

TEST(IoAtomicFile, WritesAndReplaces) {
  ScratchDir dir("io_atomic_write");
  const fs::path path = dir / "out.txt";
  write_file_atomically(path, [](std::ostream& out) { out << "first"; });
  EXPECT_EQ(read_text(path), "first");
  write_file_atomically(path, [](std::ostream& out) { out << "second\n"; });
  EXPECT_EQ(read_text(path), "second\n");
  EXPECT_EQ(count_files(dir.path()), 1);
}

TEST(IoAtomicFile, ThrowingWriterKeepsOldContentAndLeavesNoTemporary) {
  ScratchDir dir("io_atomic_throw");
  const fs::path path = dir / "keep.txt";
  write_file_atomically(path, [](std::ostream& out) { out << "old content"; });
  struct WriterFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
  };
  EXPECT_THROW(write_file_atomically(path,
                                     [](std::ostream& out) {
                                       out << std::string(100000, 'x');
                                       throw WriterFailure("stop half way");
                                     }),
               WriterFailure);
  EXPECT_EQ(read_text(path), "old content");
  EXPECT_EQ(count_files(dir.path()), 1);

  // Same for a first write: no file at all afterwards.
  const fs::path fresh = dir / "fresh.txt";
  EXPECT_THROW(write_file_atomically(fresh, [](std::ostream&) { throw InputError("bad"); }),
               InputError);
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(count_files(dir.path()), 1);
}

TEST(IoAtomicFile, MissingFolderIsInputErrorNamingThePath) {
  ScratchDir dir("io_atomic_folder");
  const fs::path path = dir / "no_such_folder" / "out.vtu";
  try {
    write_file_atomically(path, [](std::ostream& out) { out << "x"; });
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
  // A folder in the way of the target.
  fs::create_directories(dir / "taken.txt");
  EXPECT_THROW(write_file_atomically(dir / "taken.txt", [](std::ostream& out) { out << "x"; }),
               InputError);
  EXPECT_EQ(count_files(dir.path()), 1);
}

TEST(IoAtomicFile, MeshWriterFailureKeepsPreviousMesh) {
  ScratchDir dir("io_atomic_mesh");
  const fs::path path = dir / "mesh.vtu";
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  write_tet_mesh(path, mesh);
  const std::string before = read_text(path);
  TetMesh wrong = mesh;
  VtuFields fields;
  fields.add_cell_data("stress", Eigen::MatrixXd::Zero(3, 6));  // wrong row count
  EXPECT_THROW(write_vtu(path, wrong.vertices, wrong.tets, fields), InputError);
  EXPECT_EQ(read_text(path), before);
  EXPECT_EQ(count_files(dir.path()), 1);
}

}  // namespace
}  // namespace strata
