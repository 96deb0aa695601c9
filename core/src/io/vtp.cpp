#include "strata/core/io/vtp.hpp"

#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"

namespace strata {
namespace {

void write_escaped(std::ostream& out, const std::string& text) {
  for (char c : text) {
    switch (c) {
      case '&':
        out << "&amp;";
        break;
      case '<':
        out << "&lt;";
        break;
      case '>':
        out << "&gt;";
        break;
      case '"':
        out << "&quot;";
        break;
      default:
        out << c;
    }
  }
}

template <typename Matrix>
void check_rows(const std::filesystem::path& path, const std::string& kind, const std::string& name,
                const Matrix& values, Index rows) {
  if (values.rows() != rows || values.cols() < 1)
    throw InputError("cannot write '" + path.string() + "': " + kind + " field '" + name +
                     "' has " + std::to_string(values.rows()) + " × " +
                     std::to_string(values.cols()) + " entries, expected " + std::to_string(rows) +
                     " rows");
}

template <typename Matrix>
void write_array(std::ostream& out, const char* type, const std::string& name,
                 const Matrix& values) {
  out << "        <DataArray type=\"" << type << "\" Name=\"";
  write_escaped(out, name);
  out << "\" NumberOfComponents=\"" << values.cols() << "\" format=\"ascii\">\n";
  for (Index r = 0; r < values.rows(); ++r) {
    out << "         ";
    for (Index c = 0; c < values.cols(); ++c) {
      out << ' ';
      if constexpr (std::is_integral_v<typename Matrix::Scalar>)
        out << values(r, c);
      else
        write_double(out, values(r, c));
    }
    out << '\n';
  }
  out << "        </DataArray>\n";
}

}  // namespace

void write_vtp(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX3i> triangles, const VtuFields& fields) {
  const Index num_points = positions.rows();
  const Index num_polys = triangles.rows();
  for (const auto& [name, values] : fields.point_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.point_int_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.cell_data)
    check_rows(path, "cell", name, values, num_polys);
  for (const auto& [name, values] : fields.cell_int_data)
    check_rows(path, "cell", name, values, num_polys);
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
    if (!fields.point_data.empty() || !fields.point_int_data.empty()) {
      out << "      <PointData>\n";
      for (const auto& [name, values] : fields.point_data)
        write_array(out, "Float64", name, values);
      for (const auto& [name, values] : fields.point_int_data)
        write_array(out, "Int32", name, values);
      out << "      </PointData>\n";
    }
    if (!fields.cell_data.empty() || !fields.cell_int_data.empty()) {
      out << "      <CellData>\n";
      for (const auto& [name, values] : fields.cell_data)
        write_array(out, "Float64", name, values);
      for (const auto& [name, values] : fields.cell_int_data)
        write_array(out, "Int32", name, values);
      out << "      </CellData>\n";
    }
    out << "      <Points>\n"
           "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (Index v = 0; v < num_points; ++v) {
      out << "         ";
      for (int d = 0; d < 3; ++d) {
        out << ' ';
        write_double(out, positions(v, d));
      }
      out << '\n';
    }
    out << "        </DataArray>\n      </Points>\n      <Polys>\n"
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

}  // namespace strata
