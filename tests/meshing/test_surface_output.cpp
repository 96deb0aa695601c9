// The .vtp writer, checked by independent readers: python's XML parser for ASCII, meshio for
// binary.
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

/// The numbers `script` prints.
std::vector<double> printed_numbers(const std::string& script) {
  std::istringstream output(run_python(script));
  std::vector<double> values;
  double value;
  while (output >> value)
    values.push_back(value);
  return values;
}

/// Every number of the named DataArray (or of Points, connectivity, offsets) of an ASCII .vtp,
/// read by python's XML parser.
std::vector<double> parse_ascii_array(const std::filesystem::path& path, const std::string& name) {
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
  return printed_numbers(script);
}

/// The same for a binary .vtp (appended raw, zlib, UInt64 headers), decoded by python's zlib and
/// struct after the VTK file-format document (meshio does not read .vtp).
std::vector<double> parse_binary_array(const std::filesystem::path& path, const std::string& name) {
  const std::string script =
      "import re, struct, zlib\n"
      "t=open(\"" +
      path.string() +
      "\",\"rb\").read()\n"
      "h,d=t.split(b\"<AppendedData encoding=\\\"raw\\\">\")\n"
      "assert b\"vtkZLibDataCompressor\" in h and b\"UInt64\" in h\n"
      "d=d[d.index(b\"_\")+1:]\n"
      "n=\"" +
      name +
      "\"\n"
      "tags=re.findall(rb\"<DataArray[^>]*>\",h)\n"
      "g=[x for x in tags if (b\"Name=\\\"\"+n.encode()+b\"\\\"\" in x) or (n==\"points\" and "
      "b\"Name=\" not in x)][0]\n"
      "o=int(re.search(rb\"offset=\\\"(\\d+)\\\"\",g).group(1))\n"
      "k={b\"Float64\":\"d\",b\"Int32\":\"i\",b\"Int64\":\"q\",b\"UInt8\":\"B\"}[re.search("
      "rb\"type="
      "\\\"(\\w+)\\\"\",g).group(1)]\n"
      "nb=struct.unpack_from(\"<Q\",d,o)[0]\n"
      "sizes=struct.unpack_from(\"<%dQ\"%nb,d,o+24)\n"
      "p=o+24+8*nb\n"
      "raw=b\"\"\n"
      "for c in sizes:\n"
      "  raw+=zlib.decompress(d[p:p+c]); p+=c\n"
      "v=struct.unpack(\"<%d%s\"%(len(raw)//struct.calcsize(k),k),raw)\n"
      "print(\" \".join(repr(float(x)) for x in v))\n";
  return printed_numbers(script);
}

class SurfaceOutputEncoding : public ::testing::TestWithParam<VtkEncoding> {};

TEST_P(SurfaceOutputEncoding, VtpPointsFieldsAndTrianglesReadBack) {
  if (!std::filesystem::exists(kPython)) GTEST_SKIP() << "no /usr/bin/python3";
  const bool binary = GetParam() == VtkEncoding::binary;
  const auto parse_array = binary ? parse_binary_array : parse_ascii_array;
  ScratchDir dir(binary ? "surface_vtp_binary" : "surface_vtp_ascii");
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
  write_vtp(dir / "s.vtp", points, triangles, fields, GetParam());

  const std::vector<double> read_points = parse_array(dir / "s.vtp", "points");
  ASSERT_EQ(read_points.size(), 12u);
  for (int i = 0; i < 12; ++i)
    EXPECT_EQ(read_points[i], points(i / 3, i % 3));  // raw bytes or round-trip text: exact
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

  // strata's own reader gives back the same arrays.
  const VtkFrame frame = read_vtk_frame(dir / "s.vtp");
  EXPECT_EQ(frame.type, "PolyData");
  EXPECT_TRUE((frame.points.array() == points.array()).all());
  EXPECT_TRUE((frame.point_field("displacement").array() == displacement.array()).all());
  EXPECT_EQ(frame.cell_field("face").cast<int>(), Eigen::VectorXi::LinSpaced(3, 0, 2));
}

INSTANTIATE_TEST_SUITE_P(Encodings, SurfaceOutputEncoding,
                         ::testing::Values(VtkEncoding::binary, VtkEncoding::ascii),
                         [](const ::testing::TestParamInfo<VtkEncoding>& info) {
                           return info.param == VtkEncoding::binary ? "binary" : "ascii";
                         });

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
