#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "strata/core/io/vtu.hpp"

namespace strata {
namespace {

constexpr int kVtkTetra = 10;

std::string xml_escape(const std::string& text) {
  std::string result;
  for (char c : text) {
    switch (c) {
      case '&':
        result += "&amp;";
        break;
      case '<':
        result += "&lt;";
        break;
      case '>':
        result += "&gt;";
        break;
      case '"':
        result += "&quot;";
        break;
      default:
        result += c;
    }
  }
  return result;
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

void write_array(std::ostream& out, const std::string& name, const Eigen::MatrixXd& values) {
  out << "        <DataArray type=\"Float64\" Name=\"" << xml_escape(name)
      << "\" NumberOfComponents=\"" << values.cols() << "\" format=\"ascii\">\n";
  for (Index r = 0; r < values.rows(); ++r) {
    out << "         ";
    for (Index c = 0; c < values.cols(); ++c) {
      out << ' ';
      write_double(out, values(r, c));
    }
    out << '\n';
  }
  out << "        </DataArray>\n";
}

void write_array(std::ostream& out, const std::string& name, const Eigen::MatrixXi& values) {
  out << "        <DataArray type=\"Int32\" Name=\"" << xml_escape(name)
      << "\" NumberOfComponents=\"" << values.cols() << "\" format=\"ascii\">\n";
  for (Index r = 0; r < values.rows(); ++r) {
    out << "         ";
    for (Index c = 0; c < values.cols(); ++c)
      out << ' ' << values(r, c);
    out << '\n';
  }
  out << "        </DataArray>\n";
}

}  // namespace

void write_vtu(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX4i> tets, const VtuFields& fields) {
  const Index num_points = positions.rows();
  const Index num_cells = tets.rows();
  for (const auto& [name, values] : fields.point_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.point_int_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.cell_data)
    check_rows(path, "cell", name, values, num_cells);
  for (const auto& [name, values] : fields.cell_int_data)
    check_rows(path, "cell", name, values, num_cells);

  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
           "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << num_points << "\" NumberOfCells=\"" << num_cells
        << "\">\n";
    if (!fields.point_data.empty() || !fields.point_int_data.empty()) {
      out << "      <PointData>\n";
      for (const auto& [name, values] : fields.point_data)
        write_array(out, name, values);
      for (const auto& [name, values] : fields.point_int_data)
        write_array(out, name, values);
      out << "      </PointData>\n";
    }
    if (!fields.cell_data.empty() || !fields.cell_int_data.empty()) {
      out << "      <CellData>\n";
      for (const auto& [name, values] : fields.cell_data)
        write_array(out, name, values);
      for (const auto& [name, values] : fields.cell_int_data)
        write_array(out, name, values);
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
    out << "        </DataArray>\n      </Points>\n      <Cells>\n"
           "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (Index t = 0; t < num_cells; ++t)
      out << "          " << tets(t, 0) << ' ' << tets(t, 1) << ' ' << tets(t, 2) << ' '
          << tets(t, 3) << '\n';
    out << "        </DataArray>\n"
           "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (Index t = 0; t < num_cells; ++t)
      out << (t % 16 == 0 ? "          " : " ") << 4 * (t + 1)
          << (t % 16 == 15 || t + 1 == num_cells ? "\n" : "");
    out << "        </DataArray>\n"
           "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (Index t = 0; t < num_cells; ++t)
      out << (t % 16 == 0 ? "          " : " ") << kVtkTetra
          << (t % 16 == 15 || t + 1 == num_cells ? "\n" : "");
    out << "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
           "</VTKFile>\n";
  });
}

void write_vtu(const std::filesystem::path& path, const TetMesh& mesh) {
  write_vtu(path, mesh.vertices, mesh.tets);
}

}  // namespace strata
