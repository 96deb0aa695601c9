#include "strata/hierarchy/refinement_stress_jump_indicator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/fem/isotropic_stress.hpp"
#include "strata/hierarchy/tree_point_location.hpp"

namespace strata {
namespace {

// Outward faces of a positively oriented tet; face k is opposite vertex k.
constexpr int kOppositeFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct FaceKey {
  std::array<int, 3> vertices;
  int tet;
  int face;
};

// The active node containing p below `root`, or kNoNode.
NodeId active_node_at(const TetTree& tree, const std::vector<int>& node_tet, NodeId n,
                      const Vector3d& p) {
  while (node_tet[n] < 0) {
    if (tree.is_leaf(n)) return kNoNode;
    n = descend_to_point(tree, n, p, tree.level(n) + 1).node;
  }
  return n;
}

}  // namespace

StressJumpIndicator::StressJumpIndicator(double stress_floor) : m_stress_floor(stress_floor) {
  if (!(stress_floor > 0.0) || !std::isfinite(stress_floor))
    throw InputError("StressJumpIndicator: stress_floor must be a positive number");
}

MatrixX4i StressJumpIndicator::face_neighbours(const CutState& state) {
  const TetMesh& mesh = state.flat.mesh;
  const Index num_tets = mesh.tets.rows();
  MatrixX4i neighbours = MatrixX4i::Constant(num_tets, 4, -1);
  std::vector<FaceKey> faces;
  faces.reserve(4 * static_cast<std::size_t>(num_tets));
  for (Index t = 0; t < num_tets; ++t)
    for (int k = 0; k < 4; ++k) {
      FaceKey key{{mesh.tets(t, kOppositeFaces[k][0]), mesh.tets(t, kOppositeFaces[k][1]),
                   mesh.tets(t, kOppositeFaces[k][2])},
                  static_cast<int>(t),
                  k};
      std::sort(key.vertices.begin(), key.vertices.end());
      faces.push_back(key);
    }
  std::sort(faces.begin(), faces.end(),
            [](const FaceKey& a, const FaceKey& b) { return a.vertices < b.vertices; });
  for (std::size_t i = 0; i + 1 < faces.size(); ++i)
    if (faces[i].vertices == faces[i + 1].vertices) {
      neighbours(faces[i].tet, faces[i].face) = faces[i + 1].tet;
      neighbours(faces[i + 1].tet, faces[i + 1].face) = faces[i].tet;
    }

  // Unmatched faces: the body's surface or a non-conforming interface; locate the point just
  // outside the face centre.
  const TetTree& tree = state.tree;
  std::vector<int> node_tet(static_cast<std::size_t>(tree.pool_size()), -1);
  for (Index t = 0; t < num_tets; ++t)
    node_tet[state.flat.tet_nodes[t]] = static_cast<int>(t);
  std::optional<TreePointLocator> locator;
  for (Index t = 0; t < num_tets; ++t)
    for (int k = 0; k < 4; ++k) {
      if (neighbours(t, k) >= 0) continue;
      if (!locator) locator.emplace(tree);
      Vector3d centre = Vector3d::Zero();
      Vector3d face_centre = Vector3d::Zero();
      for (int i = 0; i < 4; ++i)
        centre += 0.25 * mesh.vertices.row(mesh.tets(t, i)).transpose();
      for (int i = 0; i < 3; ++i)
        face_centre += mesh.vertices.row(mesh.tets(t, kOppositeFaces[k][i])).transpose() / 3.0;
      const Vector3d outside = face_centre + 1e-6 * (face_centre - centre);
      const std::optional<TreeLocation> root = locator->locate_root(outside, 0.0);
      if (!root) continue;
      const NodeId n = active_node_at(tree, node_tet, root->node, outside);
      if (n != kNoNode && node_tet[n] != static_cast<int>(t)) neighbours(t, k) = node_tet[n];
    }
  return neighbours;
}

void StressJumpIndicator::evaluate(const CutState& state, VectorXd& eta) const {
  const MatrixX4i& tets = state.flat.mesh.tets;
  STRATA_VERIFY(state.positions.size() == 3 * state.flat.mesh.vertices.rows() &&
                    state.fields.cauchy_stress.rows() == tets.rows(),
                "StressJumpIndicator: CutState arrays do not match the flattened cut");
  const double scale =
      std::max(volume_rms_stress(state), m_stress_floor * state.material.youngs_modulus);
  const MatrixX4i neighbours = face_neighbours(state);
  eta.resize(tets.rows());
  for (Index t = 0; t < tets.rows(); ++t) {
    const Matrix3d sigma = from_voigt(state.fields.cauchy_stress.row(t).transpose());
    double jump = 0.0;
    double area = 0.0;
    for (int k = 0; k < 4; ++k) {
      const int* f = kOppositeFaces[k];
      const Vector3d a = state.positions.segment<3>(3 * tets(t, f[0]));
      const Vector3d normal = 0.5 * (state.positions.segment<3>(3 * tets(t, f[1])) - a)
                                        .cross(state.positions.segment<3>(3 * tets(t, f[2])) - a);
      area += normal.norm();
      const int nb = neighbours(t, k);
      if (nb < 0) continue;
      const Matrix3d other = from_voigt(state.fields.cauchy_stress.row(nb).transpose());
      jump += ((sigma - other) * normal).norm();
    }
    eta[t] = area > 0.0 ? jump / (scale * area) : 0.0;
  }
}

}  // namespace strata
