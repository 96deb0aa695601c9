// The .vtp writer, checked by an independent XML parser (/usr/bin/python3, xml.etree).
#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>

#include "core/io_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/vtp.hpp"
#include "strata/meshing/surface_binding.hpp"

namespace strata {
namespace {

using testing::ScratchDir;

const char* const kPython = "/usr/bin/python3";

std::string run_python(const std::string& script) {
  const std::string command = std::string(kPython) + " -c '" + script + "' 2>&1";
  std::string output;
  if (FILE* pipe = ::popen(command.c_str(), "r")) {
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), pipe))
      output += buffer;
    ::pclose(pipe);
  }
  return output;
}

/// Prints every number of the named DataArray (or of Points, connectivity, offsets) on one line.
std::vector<double> parse_array(const std::filesystem::path& path, const std::string& name) {
  const std::string script =
      "import xml.etree.ElementTree as E\n"
      "r=E.parse(\"" +
      path.string() +
      "\").getroot()\n"
      "assert r.get(\"type\")==\"PolyData\"\n"
      "p=r.find(\"PolyData/Piece\")\n"
      "a=[d for d in p.iter(\"DataArray\") if d.get(\"Name\",\"points\")==\"" +
      name +
      "\"][0]\n"
      "print(\" \".join(repr(float(x)) for x in a.text.split()))\n";
  std::istringstream output(run_python(script));
  std::vector<double> values;
  double value;
  while (output >> value)
    values.push_back(value);
  return values;
}

TEST(SurfaceOutput, VtpPointsFieldsAndTrianglesReadBack) {
  if (!std::filesystem::exists(kPython)) GTEST_SKIP() << "no /usr/bin/python3";
  ScratchDir dir("surface_vtp");
  MatrixX3d points(4, 3);
  points << 0, 0, 0, 1.0 / 3.0, 0, 0, 0, 1e-17, 0, 0.1, 0.2, 0.7;
  MatrixX3i triangles(3, 3);
  triangles << 0, 2, 1, 0, 1, 3, 1, 2, 3;
  VtuFields fields;
  const Eigen::MatrixXd displacement = Eigen::MatrixXd::Random(4, 3);
  const Eigen::VectorXd offset = Eigen::VectorXd::Random(4);
  fields.add_point_data("displacement", displacement);
  fields.add_point_data("displacement_map", offset);
  fields.add_cell_data("face", Eigen::VectorXi::LinSpaced(3, 0, 2));
  write_vtp(dir / "s.vtp", points, triangles, fields);

  const std::vector<double> read_points = parse_array(dir / "s.vtp", "points");
  ASSERT_EQ(read_points.size(), 12u);
  for (int i = 0; i < 12; ++i)
    EXPECT_EQ(read_points[i], points(i / 3, i % 3));  // shortest round-trip text: exact
  const std::vector<double> connectivity = parse_array(dir / "s.vtp", "connectivity");
  ASSERT_EQ(connectivity.size(), 9u);
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(connectivity[i], triangles(i / 3, i % 3));
  EXPECT_EQ(parse_array(dir / "s.vtp", "offsets"), (std::vector<double>{3, 6, 9}));
  const std::vector<double> read_displacement = parse_array(dir / "s.vtp", "displacement");
  ASSERT_EQ(read_displacement.size(), 12u);
  for (int i = 0; i < 12; ++i)
    EXPECT_EQ(read_displacement[i], displacement(i / 3, i % 3));
  const std::vector<double> read_offset = parse_array(dir / "s.vtp", "displacement_map");
  ASSERT_EQ(read_offset.size(), 4u);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(read_offset[i], offset(i));
  EXPECT_EQ(parse_array(dir / "s.vtp", "face"), (std::vector<double>{0, 1, 2}));
}

TEST(SurfaceOutput, VtpRejectsMismatchedFields) {
  ScratchDir dir("surface_vtp_bad");
  MatrixX3d points = MatrixX3d::Zero(3, 3);
  MatrixX3i triangles(1, 3);
  triangles << 0, 1, 2;
  VtuFields fields;
  fields.add_point_data("displacement", Eigen::MatrixXd::Zero(2, 3));
  try {
    write_vtp(dir / "bad.vtp", points, triangles, fields);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("displacement"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("bad.vtp"), std::string::npos);
  }
  triangles(0, 2) = 3;
  EXPECT_THROW(write_vtp(dir / "bad.vtp", points, triangles), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtp"));
}

}  // namespace
}  // namespace strata
