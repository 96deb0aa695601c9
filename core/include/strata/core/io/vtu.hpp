#pragma once
/// \file vtu.hpp
/// VTK XML unstructured grids (.vtu): tet meshes and simulation frames for ParaView.
/// Format: https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

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

/// Writes one frame as an ASCII .vtu, atomically: `positions` (#V × 3, current positions), `tets`
/// (#T × 4, VTK cell type 10) and the named `fields` (Float64 / Int32 arrays). Doubles are written
/// in shortest round-trip form, so reading gives back the identical values. Throws InputError
/// naming the path and field when a field's row count does not match #V or #T.
void write_vtu(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX4i> tets, const VtuFields& fields = {});

/// Writes a rest mesh as .vtu (no fields).
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh);

/// Reads the points and the tetrahedra (cell type 10) of a single-piece UnstructuredGrid .vtu;
/// other cell types and all point/cell data are ignored. DataArrays may be ASCII or inline
/// base64 binary (uncompressed, little endian); appended and compressed data are rejected.
/// Throws InputError naming the file (and line where known) on malformed input or no tets.
TetMesh read_vtu(const std::filesystem::path& path);

}  // namespace strata
