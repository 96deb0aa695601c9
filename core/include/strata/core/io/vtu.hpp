#pragma once
/// \file vtu.hpp
/// VTK XML unstructured grids (.vtu): tet meshes and simulation frames for ParaView.
/// Format: https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// How the VTK XML writers store their arrays. Both are exact: binary holds the doubles' bytes,
/// ASCII their shortest round-trip text.
enum class VtkEncoding {
  binary,  ///< appended raw data, zlib-compressed (vtkZLibDataCompressor); several times smaller
  ascii,   ///< text arrays, readable in an editor
};

/// Named per-vertex and per-tet arrays written with a frame. Each matrix has one row per vertex
/// (#V × k) or per tet (#T × k) and k components: 1 for scalars, 3 for vectors, 6 for symmetric
/// tensors. ParaView reads 6 components as (xx, yy, zz, xy, yz, xz).
struct VtuFields {
  std::vector<std::pair<std::string, Eigen::MatrixXd>> point_data;      ///< e.g. "velocity" #V × 3
  std::vector<std::pair<std::string, Eigen::MatrixXi>> point_int_data;  ///< e.g. "pinned" #V × 1
  std::vector<std::pair<std::string, Eigen::MatrixXd>> cell_data;       ///< e.g. "stress" #T × 6
  std::vector<std::pair<std::string, Eigen::MatrixXi>> cell_int_data;   ///< e.g. "level" #T × 1

  /// Adds a #V × k point field; integer matrices become Int32 arrays, others Float64.
  template <typename Derived>
  void add_point_data(std::string name, const Eigen::MatrixBase<Derived>& values) {
    if constexpr (std::is_integral_v<typename Derived::Scalar>)
      point_int_data.emplace_back(std::move(name), values.template cast<int>());
    else
      point_data.emplace_back(std::move(name), values.template cast<double>());
  }
  /// Adds a #T × k cell field; integer matrices become Int32 arrays, others Float64.
  template <typename Derived>
  void add_cell_data(std::string name, const Eigen::MatrixBase<Derived>& values) {
    if constexpr (std::is_integral_v<typename Derived::Scalar>)
      cell_int_data.emplace_back(std::move(name), values.template cast<int>());
    else
      cell_data.emplace_back(std::move(name), values.template cast<double>());
  }
};

/// The compressed integer arrays of the last binary frame of a series (connectivity, offsets,
/// cell types, integer fields such as "level"), by array name. A frame whose integer array has
/// the same bytes as the kept one of its name reuses its zlib blocks instead of compressing it
/// again: between two cut changes a run's frames differ only in their floating-point arrays. The
/// files are byte for byte those written without a cache. One per series; not for concurrent
/// writers.
class VtuArrayCache {
 public:
  /// The compressed bytes kept under `name` when they were made from exactly `raw[0, size)`,
  /// else null.
  const std::vector<std::uint8_t>* find(const std::string& name, const std::uint8_t* raw,
                                        std::size_t size);
  /// Keeps `compressed`, made from `raw[0, size)`, under `name` (in place of what was kept).
  void keep(const std::string& name, const std::uint8_t* raw, std::size_t size,
            std::vector<std::uint8_t> compressed);

  std::size_t reused() const { return m_reused; }          ///< arrays taken from the cache
  std::size_t compressed() const { return m_compressed; }  ///< arrays compressed and kept

 private:
  struct Entry {
    std::vector<std::uint8_t> raw, compressed;
  };
  std::unordered_map<std::string, Entry> m_entries;
  std::size_t m_reused = 0, m_compressed = 0;
};

/// Writes one frame as a .vtu, atomically: `positions` (#V × 3, current positions), `tets`
/// (#T × 4, VTK cell type 10) and the named `fields` (Float64 / Int32 arrays), in `encoding`.
/// Reading gives back the identical doubles in either encoding. Throws InputError naming the path
/// and field when a field's row count does not match #V or #T. With a `cache` (binary only), the
/// integer arrays that repeat the previous frame's are not compressed again.
void write_vtu(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX4i> tets, const VtuFields& fields = {},
               VtkEncoding encoding = VtkEncoding::binary, VtuArrayCache* cache = nullptr);

/// Writes a rest mesh as .vtu (no fields).
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               VtkEncoding encoding = VtkEncoding::binary);

/// The arrays of one .vtu or .vtp frame, as read back: what a run wrote, for checks and
/// post-processing.
struct VtkFrame {
  std::string type;        ///< "UnstructuredGrid" (.vtu) or "PolyData" (.vtp)
  Eigen::MatrixXd points;  ///< #V × 3
  /// Named point (#V × k) and cell (#cells × k) arrays; integer arrays as doubles.
  std::vector<std::pair<std::string, Eigen::MatrixXd>> point_data, cell_data;
  /// The topology arrays by section and name, flat: "Cells/connectivity", "Cells/offsets",
  /// "Cells/types" of a .vtu; "Polys/connectivity", "Lines/offsets", … of a .vtp.
  std::vector<std::pair<std::string, std::vector<double>>> cells;

  /// The named array; throws InputError when the frame has none of that name.
  const Eigen::MatrixXd& point_field(const std::string& name) const;
  const Eigen::MatrixXd& cell_field(const std::string& name) const;
};

/// Reads a single-piece .vtu or .vtp in any encoding read_vtu accepts. Throws InputError naming
/// the file on malformed input or arrays whose size does not match the piece's counts.
VtkFrame read_vtk_frame(const std::filesystem::path& path);

/// Reads the points and the tetrahedra (cell type 10) of a single-piece UnstructuredGrid .vtu;
/// other cell types and all point/cell data are ignored. DataArrays may be ASCII, inline base64
/// binary or appended raw binary, each uncompressed or zlib-compressed (little endian, UInt32 or
/// UInt64 headers): what strata, ParaView and meshio write. Appended base64 data and other
/// compressors are rejected. Throws InputError naming the file (and line where known) on malformed
/// input or no tets.
TetMesh read_vtu(const std::filesystem::path& path);

}  // namespace strata
