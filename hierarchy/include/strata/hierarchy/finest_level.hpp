#pragma once
/// \file finest_level.hpp
/// Scene quantities defined on the finest level of the tree, carried onto any active cut, so that a
/// scene means the same thing on every cut (full, uniform or adaptive):
///
/// - Points (probes, point loads, the bound fine surface) are stored as a root tet plus a rest
///   position. On a cut, a point lies in the leaf that contains it and is interpolated in that
///   leaf's active ancestor: x(p) = Σ_k λ_k x_k over the active tet's corners (`embed_point`). The
///   same weights carry a point force to the active vertices (the Cᵀ of a hanging vertex).
/// - Region loads (`finest_level_loads`): the coarse mesh's boundary triangles are split as red
///   refinement splits them (four midpoint triangles per level) down to the finest level; the
///   total force is spread over the finest triangles whose three corners lie in the region exactly
///   as core's add_region_force does on a mesh (area share, a third per corner). A small loaded
///   patch inside one coarse face still pulls on that face's coarse vertices. If no finest
///   triangle qualifies, the force is split equally over the finest-level lattice points in the
///   region.
/// - Dirichlet regions (`inexact_dirichlet_nodes`): a group is exact on a cut if for every
///   finest-level point it owns (the last group whose region holds it), every active corner that
///   interpolates that point (λ > 0) is owned by the group too — then the finest vertices in the
///   region follow the prescribed motion exactly. The adaptive driver refines active tets until
///   this holds and never coarsens into a parent for which it fails ("keep them exact"). For a
///   clamped face this holds on the coarse mesh already; a small clamped patch inside a coarse face
///   forces refinement there.
///
/// Gravity needs no special treatment: the lumped masses of any cut give ρ g ∫ N_i dV exactly for a
/// constant body force, which equals the finest level's loads carried by the weights above.
#include <array>
#include <vector>

#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

/// A material point: the root (coarse tet) that holds it and its rest position [m].
struct RootPoint {
  NodeId root = kNoNode;
  Vector3d position = Vector3d::Zero();
};

/// A dead point force [N] at a material point.
struct PointLoad {
  RootPoint point;
  Vector3d force = Vector3d::Zero();
  /// Magnitude of the traction the load spreads [Pa] (|total force| / loaded finest area); 0 for a
  /// load split over lattice points (no loaded surface).
  double traction = 0.0;
};

/// A point on a flattened cut: x(p) = Σ_k weights[k] · x[vertices[k]] (flat mesh vertices).
struct CutPointWeights {
  NodeId node = kNoNode;          ///< the active tet containing the point
  std::array<int, 4> vertices{};  ///< flat mesh vertices of that tet
  Eigen::Vector4d weights;        ///< barycentric coordinates (Σ = 1; < 0 slightly outside)
};

/// The active node of `cut` containing `point` (descending from its root), with the point's
/// barycentric coordinates and the flat mesh vertices of that node. `flat` must be the flattening
/// of `cut`.
CutPointWeights embed_point(const ActiveCut& cut, const FlatTreeMesh& flat, const RootPoint& point);

/// `embed_point` for each point.
std::vector<CutPointWeights> embed_points(const ActiveCut& cut, const FlatTreeMesh& flat,
                                          const std::vector<RootPoint>& points);

/// The vertices of the finest level on the boundary of `tree`'s coarse mesh: the lattice that L
/// midpoint splits put on each coarse boundary triangle, each point once (with the root of one
/// boundary triangle that holds it). Every boundary vertex of every cut is one of them.
std::vector<RootPoint> finest_boundary_points(const TetTree& tree);

/// Region loads spread on the finest level of `tree` (see the file comment), as point loads at
/// the corners of the finest boundary triangles (or lattice points). `tolerance` [m] widens the
/// regions (region_tolerance of the coarse mesh). Throws InputError naming a load whose region is
/// malformed, whose force is not finite, or that selects no finest-level point.
std::vector<PointLoad> finest_level_loads(const TetTree& tree, const std::vector<RegionLoad>& loads,
                                          double tolerance);

/// The point loads carried onto the flat vertices of `cut`: 3·#V [N] (total force kept). With
/// `tet_traction`, also per flat tet (#T, in flat.tet_nodes order) the largest `traction` of the
/// loads embedded in it (0 where none acts).
VectorXd map_point_loads(const ActiveCut& cut, const FlatTreeMesh& flat,
                         const std::vector<PointLoad>& loads, VectorXd* tet_traction = nullptr);

/// Whether every Dirichlet group is exact on node `n` (see the file comment): each finest lattice
/// point of `n` owned by a group (the last group whose region holds it, as in dirichlet.hpp) is
/// interpolated only from corners of `n` (λ > 0) owned by that same group.
bool dirichlet_exact_on(const TetTree& tree, NodeId n, const std::vector<DirichletSpec>& groups,
                        double tolerance);

/// Active nodes of `cut` on which some group is not exact (ascending).
std::vector<NodeId> inexact_dirichlet_nodes(const ActiveCut& cut,
                                            const std::vector<DirichletSpec>& groups,
                                            double tolerance);

}  // namespace strata
