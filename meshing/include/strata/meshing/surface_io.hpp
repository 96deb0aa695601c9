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

/// Whether two triangles of a closed, edge-manifold surface intersect other than at shared
/// vertices or edges (CGAL Polygon_mesh_processing::does_self_intersect). Such a surface cannot
/// bound a polyhedral Mesh_3 domain; mesh_surface_file routes it through a level set instead.
/// Precondition: is_closed_manifold_surface(surface) (std::logic_error otherwise).
bool surface_self_intersects(const SurfaceMesh& surface);

}  // namespace strata
