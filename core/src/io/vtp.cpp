#include "strata/core/io/vtp.hpp"

#include <cstdint>
#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "vtk_xml.hpp"

namespace strata {
namespace {

/// A PolyData file whose cells (`connectivity`, `nodes` point indices each) are all of one
/// section, "Polys" or "Lines".
void write_polydata(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
                    const std::vector<int>& connectivity, int nodes, const char* section,
                    const VtuFields& fields, VtkEncoding encoding, VtuArrayCache* cache) {
  const Index num_points = positions.rows();
  const auto num_cells = static_cast<Index>(connectivity.size()) / nodes;
  vtk_xml::check_field_rows(path, fields, num_points, num_cells);
  for (int v : connectivity)
    if (v < 0 || v >= num_points)
      throw InputError("cannot write '" + path.string() + "': a " +
                       (nodes == 3 ? "triangle" : "segment") + " refers to a point outside 0.." +
                       std::to_string(num_points - 1));
  const bool lines = std::string(section) == "Lines";
  std::vector<std::int64_t> indices(connectivity.begin(), connectivity.end());
  std::vector<std::int64_t> offsets(static_cast<std::size_t>(num_cells));
  for (Index c = 0; c < num_cells; ++c)
    offsets[c] = nodes * (c + 1);
  write_file_atomically(path, [&](std::ostream& out) {
    vtk_xml::DataArrayWriter arrays(encoding, cache);
    arrays.begin_file(out, "PolyData");
    out << "  <PolyData>\n"
        << "    <Piece NumberOfPoints=\"" << num_points << "\" NumberOfVerts=\"0\" NumberOfLines=\""
        << (lines ? num_cells : 0) << "\" NumberOfStrips=\"0\" NumberOfPolys=\""
        << (lines ? 0 : num_cells) << "\">\n";
    arrays.write_fields_and_points(out, fields, positions);
    out << "      <" << section << ">\n";
    arrays.write(out, "connectivity", nodes, indices);
    arrays.write(out, "offsets", 1, offsets);
    out << "      </" << section << ">\n    </Piece>\n  </PolyData>\n";
    arrays.end_file(out);
  });
}

}  // namespace

void write_vtp(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX3i> triangles, const VtuFields& fields, VtkEncoding encoding,
               VtuArrayCache* cache) {
  std::vector<int> connectivity;
  connectivity.reserve(3 * triangles.rows());
  for (Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      connectivity.push_back(triangles(f, k));
  write_polydata(path, positions, connectivity, 3, "Polys", fields, encoding, cache);
}

void write_vtp_lines(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
                     const std::vector<std::array<int, 2>>& segments, const VtuFields& fields,
                     VtkEncoding encoding) {
  std::vector<int> connectivity;
  connectivity.reserve(2 * segments.size());
  for (const auto& [a, b] : segments) {
    connectivity.push_back(a);
    connectivity.push_back(b);
  }
  write_polydata(path, positions, connectivity, 2, "Lines", fields, encoding, nullptr);
}

}  // namespace strata
