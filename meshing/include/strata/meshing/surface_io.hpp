#pragma once
/// \file surface_io.hpp
/// Reading triangle surfaces from OFF, OBJ, PLY and STL files (CGAL's readers, kept private).
#include <filesystem>

#include "strata/meshing/surface_mesh.hpp"

namespace strata {

/// Reads a surface; the format comes from the extension (.off, .obj, .ply, .stl, any case).
/// Polygons with more than three corners are split into triangle fans (corner 0, k, k+1), so the
/// orientation of the file is kept. Degenerate triangles are kept (see surface_topology and
/// remove_degenerate_triangles). Throws InputError with one line naming the file when it is
/// missing, has an unknown extension, cannot be parsed, has non-finite coordinates or an index out
/// of range, has no triangle, or has only degenerate triangles.
SurfaceMesh read_surface(const std::filesystem::path& path);

}  // namespace strata
