#include "vtk_xml.hpp"

#include "strata/core/common/error.hpp"
#include "strata/core/io/number_text.hpp"

namespace strata::vtk_xml {
namespace {

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
  out << "        <DataArray type=\"" << type << "\" Name=\"" << escape(name)
      << "\" NumberOfComponents=\"" << values.cols() << "\" format=\"ascii\">\n";
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

std::string escape(const std::string& text) {
  std::string result;
  result.reserve(text.size());
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

void check_field_rows(const std::filesystem::path& path, const VtuFields& fields, Index num_points,
                      Index num_cells) {
  for (const auto& [name, values] : fields.point_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.point_int_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.cell_data)
    check_rows(path, "cell", name, values, num_cells);
  for (const auto& [name, values] : fields.cell_int_data)
    check_rows(path, "cell", name, values, num_cells);
}

void write_data_array(std::ostream& out, const std::string& name, const Eigen::MatrixXd& values) {
  write_array(out, "Float64", name, values);
}

void write_data_array(std::ostream& out, const std::string& name, const Eigen::MatrixXi& values) {
  write_array(out, "Int32", name, values);
}

void write_fields_and_points(std::ostream& out, const VtuFields& fields,
                             ConstRef<MatrixX3d> positions) {
  if (!fields.point_data.empty() || !fields.point_int_data.empty()) {
    out << "      <PointData>\n";
    for (const auto& [name, values] : fields.point_data)
      write_data_array(out, name, values);
    for (const auto& [name, values] : fields.point_int_data)
      write_data_array(out, name, values);
    out << "      </PointData>\n";
  }
  if (!fields.cell_data.empty() || !fields.cell_int_data.empty()) {
    out << "      <CellData>\n";
    for (const auto& [name, values] : fields.cell_data)
      write_data_array(out, name, values);
    for (const auto& [name, values] : fields.cell_int_data)
      write_data_array(out, name, values);
    out << "      </CellData>\n";
  }
  out << "      <Points>\n"
         "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Index v = 0; v < positions.rows(); ++v) {
    out << "         ";
    for (int d = 0; d < 3; ++d) {
      out << ' ';
      write_double(out, positions(v, d));
    }
    out << '\n';
  }
  out << "        </DataArray>\n      </Points>\n";
}

}  // namespace strata::vtk_xml
