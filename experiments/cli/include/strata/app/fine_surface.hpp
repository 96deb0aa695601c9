#pragma once
/// \file fine_surface.hpp
/// The scene's fine surface (the render mesh, `mesh.surface`) carried by the simulation mesh: bound
/// once at the start of a run (barycentric coordinates in the containing or nearest rest tet, and
/// the displacement map over the tet mesh's boundary), then evaluated for every output frame.
#include "strata/core/io/vtu.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/surface_binding.hpp"
#include "strata/meshing/surface_mesh.hpp"

namespace strata::app {

class FineSurface {
 public:
  /// Binds `surface` (rest positions) to `rest_mesh`, the simulation's mesh.
  FineSurface(SurfaceMesh surface, const TetMesh& rest_mesh);

  /// True if `mesh` has the bound mesh's vertex and tet counts (the positions then fit).
  bool matches(const TetMesh& mesh) const;
  /// Deformed surface vertices (#Vs × 3) for the mesh positions (3·#V).
  MatrixX3d positions(ConstRef<VectorXd> mesh_positions) const;
  /// Point data of a frame: displacement (#Vs × 3, x − X) and displacement_map (#Vs, the signed
  /// offset [m] of X along the normal of the closest boundary face of the rest tet mesh).
  VtuFields fields(ConstRef<MatrixX3d> positions) const;

  const SurfaceMesh& rest() const { return m_surface; }
  const SurfaceBinding& binding() const { return m_binding; }
  double max_outside_distance() const;  ///< [m], 0 when every vertex lies in a tet
  double bind_seconds() const { return m_bind_seconds; }

 private:
  SurfaceMesh m_surface;
  SurfaceBinding m_binding;
  VectorXd m_offset;
  Index m_mesh_vertices = 0;
  Index m_mesh_tets = 0;
  double m_bind_seconds = 0.0;
};

}  // namespace strata::app
