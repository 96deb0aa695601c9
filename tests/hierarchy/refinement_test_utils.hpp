#pragma once
// Shared helpers of the refinement-criteria tests: a CutState built from prescribed displacement
// fields and finest-level point loads on a flattened cut, as the adaptive driver would fill it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_state.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"
#include "strata/hierarchy/refinement_indicator.hpp"
#include "strata/hierarchy/tree_point_location.hpp"

namespace strata::test {

/// Displacement u(X) [m] at a rest point X.
using DisplacementField = std::function<Vector3d(const Vector3d&)>;

/// A point load defined on the finest level: total force at a rest point (on the body).
struct PointLoad {
  Vector3d point;
  Vector3d force;
  double area = 0.0;  ///< loaded surface area it stands for [m²]; > 0: reported as a traction
};

/// Everything a CutState refers to, owned.
struct CutSnapshot {
  const TetTree* tree = nullptr;
  ConstrainedCut cut;
  VectorXd positions;
  TetFields fields;
  VectorXd external_forces;
  VectorXd vertex_mass;
  Material material;
  long step = 0;
  VectorXd finest_traction;  ///< #T, or empty (no finest-level tractions reported)

  CutState state() const {
    return CutState{*tree,
                    cut.flat,
                    positions,
                    fields,
                    external_forces,
                    vertex_mass,
                    material,
                    step,
                    finest_traction.size() > 0 ? &finest_traction : nullptr};
  }
};

/// The active node containing rest point p and p's barycentric coordinates in its tet_vertices.
inline TreeLocation active_location(const ActiveCut& cut, const TreePointLocator& locator,
                                    const Vector3d& p) {
  const TetTree& tree = cut.tree();
  const std::optional<TreeLocation> root = locator.locate_root(p, 1e-9);
  EXPECT_TRUE(root.has_value());
  NodeId n = root->node;
  while (!cut.is_active(n))
    n = descend_to_point(tree, n, p, tree.level(n) + 1).node;
  const Matrix3x4d x = tree.tet_positions(n);
  return {n, tet_barycentric_coordinates(p, x.col(0), x.col(1), x.col(2), x.col(3))};
}

/// Flattens `cut`, deforms it by u (evaluated at the free vertices, hanging ones follow x = C q),
/// and maps the point loads onto the vertices of the active tets containing them (barycentric
/// weights), adding gravity m·g.
inline CutSnapshot make_snapshot(const ActiveCut& cut, const Material& material,
                                 const DisplacementField& u, const std::vector<PointLoad>& loads,
                                 const Vector3d& gravity = Vector3d::Zero(), long step = 0) {
  CutSnapshot s{&cut.tree(), flatten_cut(cut), {}, {}, {}, {}, material, step, {}};
  const TetMesh& mesh = s.cut.flat.mesh;
  const HangingConstraints& hc = s.cut.constraints;
  VectorXd x = flatten(mesh.vertices);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    x.segment<3>(3 * v) += u(mesh.vertices.row(v).transpose());
  s.positions = hc.expand(hc.restrict_to_free(x));
  const ElasticModel model(mesh.vertices, mesh.tets, material);
  s.fields = model.tet_fields(s.positions);
  s.vertex_mass = lumped_vertex_mass(model.rest_data().rest_volume, mesh.tets, mesh.vertices.rows(),
                                     material.density);
  s.external_forces = VectorXd::Zero(3 * mesh.vertices.rows());
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    s.external_forces.segment<3>(3 * v) = s.vertex_mass[v] * gravity;
  if (!loads.empty()) {
    const TreePointLocator locator(cut.tree());
    for (const PointLoad& load : loads) {
      const TreeLocation at = active_location(cut, locator, load.point);
      const std::array<int, 4> corners = cut.tree().tet_vertices(at.node);
      if (load.area > 0.0) {
        if (s.finest_traction.size() == 0) s.finest_traction = VectorXd::Zero(mesh.tets.rows());
        const auto t =
            std::find(s.cut.flat.tet_nodes.begin(), s.cut.flat.tet_nodes.end(), at.node) -
            s.cut.flat.tet_nodes.begin();
        s.finest_traction[t] = std::max(s.finest_traction[t], load.force.norm() / load.area);
      }
      for (int i = 0; i < 4; ++i)
        s.external_forces.segment<3>(3 * s.cut.flat.mesh_vertices[corners[i]]) +=
            at.barycentric[i] * load.force;
    }
  }
  return s;
}

/// The mixed cut of the criteria tests: a few roots refined, one child refined again.
inline ActiveCut mixed_cut(TetTree& tree) {
  ActiveCut cut(tree);
  for (const NodeId r : {3, 40, 41, 100, 200})
    cut.refine(r);
  cut.refine(tree.child(40, 2));
  return cut;
}

/// No displacement.
inline Vector3d no_motion(const Vector3d&) {
  return Vector3d::Zero();
}

/// The test slab [0, 1] × [0, 1] × [0, 0.25] (times `scale`), 6 × 6 × 2 cells, 432 tets.
inline const Vector3d kSlabMax(1.0, 1.0, 0.25);

inline TetMesh slab(double scale = 1.0) {
  return box_tet_mesh(Vector3d::Zero(), scale * kSlabMax, {6, 6, 2});
}

inline Material test_material(double youngs_modulus = 1e6) {
  Material m;
  m.model = MaterialModel::neohookean;
  m.youngs_modulus = youngs_modulus;
  m.poisson_ratio = 0.3;
  m.density = 1000.0;
  return m;
}

inline Matrix3d affine_gradient() {
  Matrix3d G;
  G << 0.02, 0.01, -0.005,  //
      0.003, -0.01, 0.004,  //
      0.0, 0.006, 0.015;
  return G;
}

// A smooth bump of the top surface around `centre` (same strain at every scale s when lengths
// scale by s).
inline DisplacementField bump(const Vector3d& centre, double radius, double depth) {
  return [=](const Vector3d& X) -> Vector3d {
    const double r2 = (X - centre).squaredNorm() / (radius * radius);
    return Vector3d(0.0, 0.0, -depth * std::exp(-r2));
  };
}

inline bool on_slab_surface(const Vector3d& X, double scale = 1.0) {
  for (int d = 0; d < 3; ++d)
    if (std::abs(X[d]) < 1e-12 || std::abs(X[d] - scale * kSlabMax[d]) < 1e-12) return true;
  return false;
}

// Tractions of the current stress: minus the elastic force at the body's surface vertices.
inline void set_surface_tractions(CutSnapshot& s, const Vector3d& gravity) {
  const TetMesh& mesh = s.cut.flat.mesh;
  const ElasticModel model(mesh.vertices, mesh.tets, s.material);
  VectorXd f;
  model.forces(s.positions, f);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const bool surface = on_slab_surface(mesh.vertices.row(v).transpose());
    s.external_forces.segment<3>(3 * v) =
        s.vertex_mass[v] * gravity - (surface ? Vector3d(f.segment<3>(3 * v)) : Vector3d::Zero());
  }
}

/// Rest centroid of a node.
inline Vector3d node_centroid(const TetTree& tree, NodeId n) {
  return tree.tet_positions(n).rowwise().mean();
}

}  // namespace strata::test
