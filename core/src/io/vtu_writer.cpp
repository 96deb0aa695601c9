#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
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
               ConstRef<MatrixX4i> tets, const VtuFields& fields, VtkEncoding encoding,
               VtuArrayCache* cache) {
  const Index num_points = positions.rows();
  const Index num_cells = tets.rows();
  vtk_xml::check_field_rows(path, fields, num_points, num_cells);

  std::vector<std::int64_t> connectivity(static_cast<std::size_t>(4 * num_cells));
  std::vector<std::int64_t> offsets(static_cast<std::size_t>(num_cells));
  tbb::parallel_for(tbb::blocked_range<Index>(0, num_cells, 4096),
                    [&](const tbb::blocked_range<Index>& range) {
                      for (Index t = range.begin(); t != range.end(); ++t) {
                        for (int k = 0; k < 4; ++k)
                          connectivity[4 * t + k] = tets(t, k);
                        offsets[t] = 4 * (t + 1);
                      }
                    });
  const std::vector<std::uint8_t> types(static_cast<std::size_t>(num_cells), kVtkTetra);

  write_file_atomically(path, [&](std::ostream& out) {
    vtk_xml::DataArrayWriter arrays(encoding, cache);
    arrays.begin_file(out, "UnstructuredGrid");
    out << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << num_points << "\" NumberOfCells=\"" << num_cells
        << "\">\n";
    arrays.write_fields_and_points(out, fields, positions);
    out << "      <Cells>\n";
    arrays.write(out, "connectivity", 4, connectivity);
    arrays.write(out, "offsets", 1, offsets);
    arrays.write(out, "types", 1, types);
    out << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
    arrays.end_file(out);
  });
}

void write_vtu(const std::filesystem::path& path, const TetMesh& mesh, VtkEncoding encoding) {
  write_vtu(path, mesh.vertices, mesh.tets, {}, encoding);
}

}  // namespace strata
