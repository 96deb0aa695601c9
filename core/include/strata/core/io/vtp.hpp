#pragma once
/// \file vtp.hpp
/// VTK XML PolyData (.vtp): triangle surfaces with point and cell fields for ParaView, e.g. the
/// deformed fine surface of a run. Same conventions as vtu.hpp (binary or ASCII, exact, atomic).
/// Format: https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html
#include <array>
#include <filesystem>
#include <vector>

#include "strata/core/io/vtu.hpp"

namespace strata {

/// Writes a triangle surface as a .vtp in `encoding`, atomically: `positions` (#V × 3), `triangles`
/// (#F × 3, written as Polys) and the named `fields` (point data #V × k, cell data #F × k;
/// Float64 / Int32). Throws InputError naming the path and field when a field's row count does not
/// match #V or #F, or a triangle index is out of range. With a `cache` (binary only), the integer
/// arrays that repeat the previous frame's are not compressed again (VtuArrayCache).
void write_vtp(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
               ConstRef<MatrixX3i> triangles, const VtuFields& fields = {},
               VtkEncoding encoding = VtkEncoding::binary, VtuArrayCache* cache = nullptr);

/// Writes line segments (`segments` #L pairs of point indices, written as Lines) as a .vtp in
/// `encoding`, atomically, with point fields (#V × k) and cell fields (#L × k), e.g. a curve
/// skeleton.
void write_vtp_lines(const std::filesystem::path& path, ConstRef<MatrixX3d> positions,
                     const std::vector<std::array<int, 2>>& segments, const VtuFields& fields = {},
                     VtkEncoding encoding = VtkEncoding::binary);

}  // namespace strata
