#pragma once
/// \file curve_skeleton.hpp
/// The curve skeleton of a closed surface by CGAL's mean-curvature-flow skeletonization
/// (Tagliasacchi et al. 2012, `CGAL::extract_mean_curvature_flow_skeleton`): the surface contracts
/// along its mean-curvature flow to a graph of curves near the medial axis, and every surface
/// vertex is recorded against the skeleton point it collapsed to.
#include <string>

#include "strata/core/common/types.hpp"
#include "strata/meshing/surface_mesh.hpp"

namespace strata {

struct CurveSkeleton {
  MatrixX3d points;                             ///< #K × 3 skeleton vertices [m]
  Eigen::Matrix<int, Eigen::Dynamic, 2> edges;  ///< #E × 2 segments between them
  VectorXi owner;        ///< #V of the surface: the skeleton vertex each surface vertex maps to
  double seconds = 0.0;  ///< wall time of the skeletonization
};

/// Skeletonizes a closed, consistently oriented triangle surface. Surface vertices CGAL does not
/// assign (none, for a closed manifold) go to the nearest skeleton vertex. Throws InputError
/// naming `where` for a surface that is not a closed 2-manifold or has fewer than 4 vertices.
CurveSkeleton curve_skeleton(const SurfaceMesh& surface, const std::string& where);

/// Whether every skeleton vertex is reachable from vertex 0 along the edges.
bool is_connected(const CurveSkeleton& skeleton);

}  // namespace strata
