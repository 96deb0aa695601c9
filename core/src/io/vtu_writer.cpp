#include <ostream>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "strata/core/io/vtu.hpp"

#include "vtk_xml.hpp"

namespace strata {

namespace {
constexpr int kVtkTetra = 10;  ///< VTK cell type of a linear tetrahedron
}  // namespace

void write_vtu(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX4i> tets, const VtuFields& fields) {
  const Index num_points = positions.rows();
  const Index num_cells = tets.rows();
  vtk_xml::check_field_rows(path, fields, num_points, num_cells);

  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
           "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << num_points << "\" NumberOfCells=\"" << num_cells
        << "\">\n";
    vtk_xml::write_fields_and_points(out, fields, positions);
    out << "            <Cells>\n"
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
