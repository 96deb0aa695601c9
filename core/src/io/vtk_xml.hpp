#pragma once
// Internal helpers shared by the VTK XML writers (.vtu, .vtp): escaping, field checks and the
// DataArrays of one file in either encoding. Not installed.
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "strata/core/io/vtu.hpp"

namespace strata::vtk_xml {

/// `text` with &, <, > and " replaced by their XML entities.
std::string escape(const std::string& text);

/// Throws InputError ("cannot write '<path>': point field 'x' has r × c entries, expected n rows")
/// unless every point field of `fields` has `num_points` rows and every cell field `num_cells`.
void check_field_rows(const std::filesystem::path& path, const VtuFields& fields, Index num_points,
                      Index num_cells);

/// The DataArrays of one VTK XML file. ASCII arrays are written in place (doubles in shortest
/// round-trip form); binary arrays become `format="appended"` references into the
/// <AppendedData encoding="raw"> block that `end_file` writes, each compressed by zlib in blocks
/// behind a UInt64 header (VTK's vtkZLibDataCompressor layout).
class DataArrayWriter {
 public:
  /// With a `cache`, binary integer arrays go through it (VtuArrayCache).
  explicit DataArrayWriter(VtkEncoding encoding, VtuArrayCache* cache = nullptr)
      : m_encoding(encoding), m_cache(cache) {}

  /// `<?xml …?>` and the `<VTKFile type="…">` start tag (with the compressor when binary).
  void begin_file(std::ostream& out, const char* type) const;

  /// One DataArray of `values`, `components` per tuple; `name` may be empty (the Points array).
  /// Float64 for double, Int32 / Int64 / UInt8 for the integer types.
  template <typename T>
  void write(std::ostream& out, const std::string& name, int components,
             const std::vector<T>& values);

  /// The <PointData> and <CellData> of `fields` (each only if non-empty), then <Points> with
  /// `positions` (#V × 3), as a piece of a .vtu or .vtp holds them.
  void write_fields_and_points(std::ostream& out, const VtuFields& fields,
                               ConstRef<MatrixX3d> positions);

  /// `</VTKFile>`, preceded by the appended data when binary.
  void end_file(std::ostream& out) const;

 private:
  /// Appends the zlib blocks of `data[0, size)` behind their UInt64 header to `into`.
  static void append_compressed(const std::uint8_t* data, std::size_t size,
                                std::vector<std::uint8_t>& into);

  VtkEncoding m_encoding;
  VtuArrayCache* m_cache;
  std::vector<std::uint8_t> m_appended;
};

}  // namespace strata::vtk_xml
