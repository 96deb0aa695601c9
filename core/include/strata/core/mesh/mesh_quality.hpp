#pragma once
/// \file mesh_quality.hpp
/// Size and shape statistics of a tet mesh, as printed by `strata info`.
#include <string>

#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

/// Statistics over all tets. Angles in degrees, lengths and volumes in the mesh's units.
/// For an empty mesh (no tets) every number except `vertices` is 0.
struct MeshQuality {
  Index vertices = 0;
  Index tets = 0;
  Index boundary_faces = 0;              ///< tet faces used by exactly one tet
  Vector3d bbox_min = Vector3d::Zero();  ///< bounding box of the vertices
  Vector3d bbox_max = Vector3d::Zero();
  double total_volume = 0.0;    ///< sum of signed tet volumes
  double min_tet_volume = 0.0;  ///< signed: negative when some tet is inverted
  double max_tet_volume = 0.0;
  double min_edge_length = 0.0;
  double max_edge_length = 0.0;
  double min_dihedral_angle = 0.0;  ///< [deg]; 70.5288° for a regular tet
  double max_dihedral_angle = 0.0;  ///< [deg]
  double min_radius_ratio = 0.0;    ///< 3·inradius / circumradius: 1 regular, 0 degenerate
  double mean_radius_ratio = 0.0;
  Index negative_tets = 0;  ///< tets with signed volume < 0
};

/// The dihedral angle [rad] of tet (x0..x3) at its edge (a, b) with a, b in 0..3: the angle between
/// the two faces sharing that edge, in [0, π].
double tet_dihedral_angle(const Matrix3x4d& x, int a, int b);

/// 3·r/R of a tet (inradius r = 3|V| / surface area, circumradius R): 1 for a regular tet, 0 for a
/// degenerate one.
double tet_radius_ratio(const Matrix3x4d& x);

/// Statistics of `mesh` in one pass over the tets plus a sort of the faces (O(#T log #T)).
/// Tet indices must be in range (validate_tet_mesh).
MeshQuality compute_mesh_quality(const TetMesh& mesh);

/// A human-readable multi-line report, one quantity per line.
std::string format_mesh_quality(const MeshQuality& quality);

}  // namespace strata
