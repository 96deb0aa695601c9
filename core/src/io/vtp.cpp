#include "strata/core/io/vtp.hpp"

#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "vtk_xml.hpp"

namespace strata {

void write_vtp(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX3i> triangles, const VtuFields& fields) {
  const Index num_points = positions.rows();
  const Index num_polys = triangles.rows();
  vtk_xml::check_field_rows(path, fields, num_points, num_polys);
  if (num_polys > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= num_points))
    throw InputError("cannot write '" + path.string() +
                     "': a triangle refers to a point outside 0.." +
                     std::to_string(num_points - 1));

  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
           "  <PolyData>\n"
        << "    <Piece NumberOfPoints=\"" << num_points
        << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\""
        << num_polys << "\">\n";
    vtk_xml::write_fields_and_points(out, fields, positions);
    out << "            <Polys>\n"
           "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (Index f = 0; f < num_polys; ++f)
      out << "          " << triangles(f, 0) << ' ' << triangles(f, 1) << ' ' << triangles(f, 2)
          << '\n';
    out << "        </DataArray>\n"
           "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (Index f = 0; f < num_polys; ++f)
      out << (f % 16 == 0 ? "          " : " ") << 3 * (f + 1)
          << (f % 16 == 15 || f + 1 == num_polys ? "\n" : "");
    out << "        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  });
}

void write_vtp_lines(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
                     const std::vector<std::array<int, 2>>& segments, const VtuFields& fields) {
  const Index num_points = positions.rows();
  const auto num_lines = static_cast<Index>(segments.size());
  vtk_xml::check_field_rows(path, fields, num_points, num_lines);
  for (const auto& [a, b] : segments)
    if (a < 0 || b < 0 || a >= num_points || b >= num_points)
      throw InputError("cannot write '" + path.string() +
                       "': a segment refers to a point outside 0.." +
                       std::to_string(num_points - 1));
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
           "  <PolyData>\n"
        << "    <Piece NumberOfPoints=\"" << num_points << "\" NumberOfVerts=\"0\" NumberOfLines=\""
        << num_lines << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
    vtk_xml::write_fields_and_points(out, fields, positions);
    out << "      <Lines>\n"
           "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& [a, b] : segments)
      out << "          " << a << ' ' << b << '\n';
    out << "        </DataArray>\n"
           "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (Index l = 0; l < num_lines; ++l)
      out << (l % 16 == 0 ? "          " : " ") << 2 * (l + 1)
          << (l % 16 == 15 || l + 1 == num_lines ? "\n" : "");
    out << "        </DataArray>\n      </Lines>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  });
}

}  // namespace strata
