#include "strata/hierarchy/cut_transfer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "strata/core/common/error.hpp"

namespace strata {

VectorXd transfer_vertex_values(const TetTree& tree, const FlatTreeMesh& source,
                                ConstRef<VectorXd> source_values, const FlatTreeMesh& target) {
  STRATA_VERIFY(source_values.size() == 3 * static_cast<Index>(source.tree_vertices.size()),
                "transfer_vertex_values: source values must have 3·#V entries");
  const std::size_t num_target = target.tree_vertices.size();
  VectorXd values(3 * static_cast<Index>(num_target));
  std::vector<char> known(num_target, 0);
  std::vector<int> missing;
  for (std::size_t v = 0; v < num_target; ++v) {
    const int tree_vertex = target.tree_vertices[v];
    const int s = static_cast<std::size_t>(tree_vertex) < source.mesh_vertices.size()
                      ? source.mesh_vertices[tree_vertex]
                      : -1;
    if (s < 0) {
      missing.push_back(static_cast<int>(v));
      continue;
    }
    values.segment<3>(3 * static_cast<Index>(v)) = source_values.segment<3>(3 * s);
    known[v] = 1;
  }
  // Parents have lower vertex levels: resolve the new vertices coarse to fine.
  std::sort(missing.begin(), missing.end(), [&](int a, int b) {
    return tree.vertex_level(target.tree_vertices[a]) < tree.vertex_level(target.tree_vertices[b]);
  });
  // The parents of a mesh vertex are vertices of the same mesh (target is a valid cut).
  for (const int v : missing) {
    const std::array<int, 2>& parents = tree.vertex_parents(target.tree_vertices[v]);
    STRATA_VERIFY(parents[0] >= 0,
                  "transfer_vertex_values: a coarse vertex of the target is not in the source");
    Vector3d value = Vector3d::Zero();
    for (const int p : parents) {
      const int t = target.mesh_vertices[p];
      STRATA_VERIFY(t >= 0 && known[t],
                    "transfer_vertex_values: a new vertex's parent is not in the target mesh");
      value += 0.5 * values.segment<3>(3 * static_cast<Index>(t));
    }
    values.segment<3>(3 * static_cast<Index>(v)) = value;
    known[v] = 1;
  }
  return values;
}

}  // namespace strata

namespace strata {

PlasticState transfer_plastic_state(const TetTree& tree, const FlatTreeMesh& source,
                                    const PlasticState& source_state, const FlatTreeMesh& target,
                                    double* max_merge_change) {
  const std::size_t num_source = source.tet_nodes.size();
  STRATA_VERIFY(source_state.num_tets() == static_cast<Index>(num_source) &&
                    source_state.plastic_inverse.size() == num_source,
                "transfer_plastic_state: the state must have one entry per source tet");
  std::unordered_map<NodeId, std::size_t> source_tet, target_tet;
  for (std::size_t t = 0; t < num_source; ++t)
    source_tet.emplace(source.tet_nodes[t], t);
  for (std::size_t t = 0; t < target.tet_nodes.size(); ++t)
    target_tet.emplace(target.tet_nodes[t], t);

  const Index num_target = static_cast<Index>(target.tet_nodes.size());
  PlasticState state;
  state.plastic_inverse.assign(num_target, Matrix3d::Zero());
  state.equivalent_strain = VectorXd::Zero(num_target);
  std::vector<double> merged_volume(num_target, 0.0);
  std::vector<char> done(num_target, 0);
  const auto rest_volume = [&](NodeId n) {
    const Matrix3x4d x = tree.tet_positions(n);
    return std::abs((x.col(1) - x.col(0)).dot((x.col(2) - x.col(0)).cross(x.col(3) - x.col(0)))) /
           6.0;
  };
  // Kept or refined: the nearest source node at or above the target node.
  for (Index t = 0; t < num_target; ++t) {
    for (NodeId n = target.tet_nodes[t]; n != kNoNode; n = tree.parent(n)) {
      const auto found = source_tet.find(n);
      if (found == source_tet.end()) continue;
      state.plastic_inverse[t] = source_state.plastic_inverse[found->second];
      state.equivalent_strain[t] = source_state.equivalent_strain[found->second];
      done[t] = 1;
      break;
    }
  }
  // Coarsened: source nodes below a target node contribute by rest volume.
  std::vector<std::vector<std::size_t>> merged(num_target);
  for (std::size_t s = 0; s < num_source; ++s) {
    for (NodeId n = tree.parent(source.tet_nodes[s]); n != kNoNode; n = tree.parent(n)) {
      const auto found = target_tet.find(n);
      if (found == target_tet.end()) continue;
      const std::size_t t = found->second;
      if (done[t]) break;
      const double volume = rest_volume(source.tet_nodes[s]);
      state.plastic_inverse[t] += volume * source_state.plastic_inverse[s];
      state.equivalent_strain[t] += volume * source_state.equivalent_strain[s];
      merged_volume[t] += volume;
      merged[t].push_back(s);
      break;
    }
  }
  double change = 0.0;
  for (Index t = 0; t < num_target; ++t) {
    if (done[t]) continue;
    if (!(merged_volume[t] > 0.0))
      throw std::logic_error("transfer_plastic_state: target tet " + std::to_string(t) +
                             " is related to no source tet");
    state.equivalent_strain[t] /= merged_volume[t];
    Matrix3d& mean = state.plastic_inverse[t];
    mean /= merged_volume[t];
    const double det = mean.determinant();
    if (det > 0.0) mean /= std::cbrt(det);
    for (std::size_t s : merged[t])
      change = std::max(change,
                        std::abs(source_state.equivalent_strain[s] - state.equivalent_strain[t]));
  }
  if (max_merge_change != nullptr) *max_merge_change = change;
  return state;
}

}  // namespace strata
