#pragma once
/// \file tetrahedralize.hpp
/// Tet meshes of a closed surface or of an implicit (signed distance) domain with CGAL Mesh_3,
/// behind plain arrays. Delaunay refinement: Jamin, Alliez, Yvinec, Boissonnat, "CGALmesh: a
/// generic framework for Delaunay mesh generation", ACM TOMS 2015.
///
/// Results are deterministic: CGAL's random generator is reseeded with `options.seed` and the
/// optimisers run without a time limit, so the same input and options give the same mesh.
/// Every returned mesh has no unused vertex and only positively oriented tets (validate_tet_mesh
/// holds); take its boundary from boundary_faces(mesh.tets).
#include <functional>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/meshing_options.hpp"
#include "strata/meshing/surface_mesh.hpp"

namespace strata {

/// Estimated tet count of meshing a volume [m³] with `options`: volume / (c · cell_size³) with
/// c = kTetsPerCellVolume (fitted on CGAL's models; real counts are within about a factor 2 and
/// grow with finer facet criteria).
double estimate_tet_count(double volume, const MeshingOptions& options);
inline constexpr double kTetsPerCellVolume = 0.1;

/// Checks the options (cell_size > 0, facet_angle in (0, 30], cell_radius_edge_ratio ≥ 2,
/// non-negative facet sizes) and that estimate_tet_count(volume) ≤ options.max_tets. InputError
/// (one line, with the estimate) otherwise.
void check_meshing_request(double volume, const MeshingOptions& options);

/// Tetrahedralises the inside of a closed, edge-manifold triangle surface (#V × 3, #F × 3; either
/// orientation) with Mesh_3's polyhedral domain; with options.sharp_features, edges whose dihedral
/// angle is sharper than options.feature_angle are protected and kept in the boundary.
/// Degenerate triangles are dropped first. InputError when the surface is open, non-manifold or
/// not a polygon mesh (mesh it through a level set instead: tetrahedralize_implicit), when the
/// request is refused by check_meshing_request, or when Mesh_3 produced no tet.
TetMesh tetrahedralize_surface(const SurfaceMesh& surface, const MeshingOptions& options);

/// Tetrahedralises { x : signed_distance(x) < 0 } inside the box [box_min, box_max] with Mesh_3's
/// implicit (labeled) domain. `signed_distance` is called from the calling thread only; it must
/// be negative inside, positive outside and positive on the box faces. The tet-count guard uses
/// `volume_estimate` [m³] when > 0, else the box's volume. InputError when the box is empty, the
/// request is refused or no tet came out.
TetMesh tetrahedralize_implicit(const std::function<double(const Vector3d&)>& signed_distance,
                                const Vector3d& box_min, const Vector3d& box_max,
                                const MeshingOptions& options, double volume_estimate = 0.0);

/// Whether `surface` can go to the polyhedral domain: a closed, edge-manifold polygon mesh after
/// dropping degenerate triangles. (CGAL's combinatorial test, the one tetrahedralize_surface uses.)
bool is_closed_manifold_surface(const SurfaceMesh& surface);

}  // namespace strata
