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

// Neighbour across each face of a positively oriented tet mesh where the face is shared (same
// three vertices), else −1; through the vertex-to-tet incidence (no sorting of faces).
MatrixX4i conforming_face_neighbours(const MatrixX4i& tets, Index num_vertices) {
  std::vector<int> start(static_cast<std::size_t>(num_vertices) + 1, 0);
  for (Index t = 0; t < tets.rows(); ++t)
    for (int i = 0; i < 4; ++i)
      ++start[tets(t, i) + 1];
  for (std::size_t v = 1; v < start.size(); ++v)
    start[v] += start[v - 1];
  std::vector<int> incident(static_cast<std::size_t>(start.back()));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (Index t = 0; t < tets.rows(); ++t)
    for (int i = 0; i < 4; ++i)
      incident[fill[tets(t, i)]++] = static_cast<int>(t);
  const auto has_vertex = [&](int s, int v) {
    return tets(s, 0) == v || tets(s, 1) == v || tets(s, 2) == v || tets(s, 3) == v;
  };
  MatrixX4i neighbours = MatrixX4i::Constant(tets.rows(), 4, -1);
  for (Index t = 0; t < tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int a = tets(t, kOppositeFaces[k][0]);
      const int b = tets(t, kOppositeFaces[k][1]);
      const int c = tets(t, kOppositeFaces[k][2]);
      for (int i = start[a]; i < start[a + 1]; ++i) {
        const int s = incident[i];
        if (s != t && has_vertex(s, b) && has_vertex(s, c)) {
          neighbours(t, k) = s;
          break;
        }
      }
    }
  return neighbours;
}

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
  const TetTree& tree = state.tree;
  const Index num_tets = mesh.tets.rows();
  MatrixX4i neighbours = conforming_face_neighbours(mesh.tets, mesh.vertices.rows());

  // Unmatched faces lie on the body's surface or on a non-conforming interface. A face on a
  // root's face that no other root shares is surface; the others find their neighbour by
  // locating the point just outside the face centre.
  MatrixX4i roots(tree.num_roots(), 4);
  for (Index r = 0; r < tree.num_roots(); ++r) {
    const std::array<int, 4> v = tree.tet_vertices(static_cast<NodeId>(r));
    roots.row(r) << v[0], v[1], v[2], v[3];
  }
  std::optional<MatrixX4i> root_neighbours;
  std::vector<int> node_tet;
  std::optional<TreePointLocator> locator;
  for (Index t = 0; t < num_tets; ++t)
    for (int k = 0; k < 4; ++k) {
      if (neighbours(t, k) >= 0) continue;
      std::array<Vector3d, 3> face;
      for (int i = 0; i < 3; ++i)
        face[i] = mesh.vertices.row(mesh.tets(t, kOppositeFaces[k][i])).transpose();
      const NodeId root = tree.node(state.flat.tet_nodes[t]).root;
      const Matrix3x4d X = tree.tet_positions(root);
      if (!root_neighbours)
        root_neighbours = conforming_face_neighbours(roots, tree.num_coarse_vertices());
      bool surface = false;
      Eigen::Vector4d lambda[3];
      for (int i = 0; i < 3; ++i)
        lambda[i] = tet_barycentric_coordinates(face[i], X.col(0), X.col(1), X.col(2), X.col(3));
      for (int j = 0; j < 4 && !surface; ++j)
        surface = (*root_neighbours)(root, j) < 0 && std::abs(lambda[0][j]) < 1e-9 &&
                  std::abs(lambda[1][j]) < 1e-9 && std::abs(lambda[2][j]) < 1e-9;
      if (surface) continue;
      if (!locator) {
        locator.emplace(tree);
        node_tet.assign(static_cast<std::size_t>(tree.pool_size()), -1);
        for (Index s = 0; s < num_tets; ++s)
          node_tet[state.flat.tet_nodes[s]] = static_cast<int>(s);
      }
      Vector3d centre = Vector3d::Zero();
      for (int i = 0; i < 4; ++i)
        centre += 0.25 * mesh.vertices.row(mesh.tets(t, i)).transpose();
      const Vector3d face_centre = (face[0] + face[1] + face[2]) / 3.0;
      const Vector3d outside = face_centre + 1e-6 * (face_centre - centre);
      const std::optional<TreeLocation> at = locator->locate_root(outside, 0.0);
      if (!at) continue;
      const NodeId n = active_node_at(tree, node_tet, at->node, outside);
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
