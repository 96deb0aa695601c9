#pragma once
// Internal helpers shared by the VTK XML writers (.vtu, .vtp, .pvd): escaping, field checks and
// ASCII DataArrays. Not installed.
#include <filesystem>
#include <ostream>
#include <string>

#include "strata/core/io/vtu.hpp"

namespace strata::vtk_xml {

/// `text` with &, <, > and " replaced by their XML entities.
std::string escape(const std::string& text);

/// Throws InputError ("cannot write '<path>': point field 'x' has r × c entries, expected n rows")
/// unless every point field of `fields` has `num_points` rows and every cell field `num_cells`.
void check_field_rows(const std::filesystem::path& path, const VtuFields& fields, Index num_points,
                      Index num_cells);

/// One ASCII DataArray (Float64 in shortest round-trip form, or Int32), rows of `values`.
void write_data_array(std::ostream& out, const std::string& name, const Eigen::MatrixXd& values);
void write_data_array(std::ostream& out, const std::string& name, const Eigen::MatrixXi& values);

/// The <PointData> and <CellData> of `fields` (each only if non-empty), then <Points> with
/// `positions` (#V × 3), as a piece of a .vtu or .vtp writes them.
void write_fields_and_points(std::ostream& out, const VtuFields& fields,
                             ConstRef<MatrixX3d> positions);

}  // namespace strata::vtk_xml
