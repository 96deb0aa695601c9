#include "strata/hierarchy/uniform_refinement.hpp"

#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

Index refine_uniformly(TetTree& tree, int level) {
  STRATA_VERIFY(level >= 0 && level <= tree.max_level(),
                "refine_uniformly: level must be in 0..max_level");
  const Index before = tree.num_nodes();
  std::vector<NodeId> front = tree.leaves();
  std::vector<NodeId> next;
  while (!front.empty()) {
    next.clear();
    for (const NodeId n : front) {
      if (tree.level(n) >= level) continue;
      const NodeId first = tree.refine(n);
      for (int k = 0; k < 8; ++k)
        next.push_back(first + k);
    }
    front.swap(next);
  }
  return tree.num_nodes() - before;
}

TetMesh uniform_refinement(const TetMesh& mesh, int levels) {
  TetTree tree(mesh, levels);
  refine_uniformly(tree, levels);
  return flatten_leaves(tree).mesh;
}

}  // namespace strata
