#include "strata/hierarchy/cut_transfer.hpp"

#include <algorithm>

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
