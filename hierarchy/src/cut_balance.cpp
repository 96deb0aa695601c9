#include "strata/hierarchy/cut_balance.hpp"

#include <algorithm>

#include "strata/hierarchy/hanging_constraints.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

std::vector<BalanceViolation> balance_violations(const ActiveCut& cut) {
  const TetTree& tree = cut.tree();
  const FlatTreeMesh flat = flatten_nodes(tree, cut.nodes());
  // Finest active tet per mesh vertex.
  std::vector<NodeId> finest(flat.tree_vertices.size(), kNoNode);
  for (std::size_t t = 0; t < flat.tet_nodes.size(); ++t) {
    const NodeId n = flat.tet_nodes[t];
    for (int i = 0; i < 4; ++i) {
      NodeId& f = finest[flat.mesh.tets(static_cast<Index>(t), i)];
      if (f == kNoNode || tree.level(f) < tree.level(n)) f = n;
    }
  }
  std::vector<BalanceViolation> violations;
  for (const HangingVertex& h : find_hanging_vertices(tree, flat)) {
    const NodeId fine = finest[h.vertex];
    if (tree.level(fine) <= h.host_level + 1) continue;
    BalanceViolation v;
    v.tree_vertex = flat.tree_vertices[h.vertex];
    v.host = h.host;
    v.host_level = h.host_level;
    v.fine_node = fine;
    v.fine_level = tree.level(fine);
    violations.push_back(v);
  }
  return violations;
}

bool is_balanced(const ActiveCut& cut) {
  return balance_violations(cut).empty();
}

Index balance_cut(ActiveCut& cut) {
  Index refined = 0;
  for (;;) {
    const std::vector<BalanceViolation> violations = balance_violations(cut);
    if (violations.empty()) return refined;
    std::vector<NodeId> hosts;
    hosts.reserve(violations.size());
    for (const BalanceViolation& v : violations)
      hosts.push_back(v.host);
    std::sort(hosts.begin(), hosts.end());
    hosts.erase(std::unique(hosts.begin(), hosts.end()), hosts.end());
    for (const NodeId host : hosts) {
      cut.refine(host);
      ++refined;
    }
  }
}

NodeId refine_balanced(ActiveCut& cut, NodeId n) {
  const NodeId first = cut.refine(n);
  balance_cut(cut);
  return first;
}

}  // namespace strata
