#include "strata/hierarchy/active_cut.hpp"

#include <algorithm>
#include <string>

#include "strata/core/common/error.hpp"

namespace strata {

ActiveCut::ActiveCut(TetTree& tree) : m_tree(&tree) {
  m_nodes.reserve(static_cast<std::size_t>(tree.num_roots()));
  for (NodeId r = 0; r < tree.num_roots(); ++r)
    activate(r);
}

ActiveCut::ActiveCut(TetTree& tree, const std::vector<NodeId>& nodes) : m_tree(&tree) {
  m_nodes.reserve(nodes.size());
  for (const NodeId n : nodes) {
    if (!tree.is_alive(n))
      throw InputError("ActiveCut: node " + std::to_string(n) + " is not a live tree node");
    if (is_active(n)) throw InputError("ActiveCut: node " + std::to_string(n) + " is listed twice");
    activate(n);
  }
  validate();
}

ActiveCut ActiveCut::uniform(TetTree& tree, int level) {
  if (level < 0 || level > tree.max_level())
    throw InputError("ActiveCut::uniform: level " + std::to_string(level) + " is not in 0.." +
                     std::to_string(tree.max_level()));
  ActiveCut cut(tree);
  std::vector<NodeId> current = cut.m_nodes;
  for (int l = 0; l < level; ++l) {
    std::vector<NodeId> next;
    next.reserve(8 * current.size());
    for (const NodeId n : current) {
      const NodeId first = tree.refine(n);
      for (int k = 0; k < 8; ++k)
        next.push_back(first + k);
    }
    current.swap(next);
  }
  cut.m_nodes.clear();
  cut.m_slot.clear();
  for (const NodeId n : current)
    cut.activate(n);
  return cut;
}

std::vector<NodeId> ActiveCut::depth_first_nodes() const {
  std::vector<NodeId> order;
  order.reserve(m_nodes.size());
  std::vector<NodeId> stack;
  for (NodeId root = static_cast<NodeId>(m_tree->num_roots()) - 1; root >= 0; --root)
    stack.push_back(root);
  while (!stack.empty()) {
    const NodeId n = stack.back();
    stack.pop_back();
    if (is_active(n)) {
      order.push_back(n);
    } else if (!m_tree->is_leaf(n)) {
      for (int k = 7; k >= 0; --k)
        stack.push_back(m_tree->node(n).first_child + k);
    }
  }
  STRATA_VERIFY(order.size() == m_nodes.size(), "depth_first_nodes: the cut is not a cut");
  return order;
}

std::vector<NodeId> ActiveCut::sorted_nodes() const {
  std::vector<NodeId> sorted = m_nodes;
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

bool ActiveCut::is_active(NodeId n) const {
  return n >= 0 && static_cast<std::size_t>(n) < m_slot.size() && m_slot[n] >= 0;
}

int ActiveCut::finest_level() const {
  int finest = 0;
  for (const NodeId n : m_nodes)
    finest = std::max(finest, m_tree->level(n));
  return finest;
}

int ActiveCut::coarsest_level() const {
  int coarsest = m_tree->max_level();
  for (const NodeId n : m_nodes)
    coarsest = std::min(coarsest, m_tree->level(n));
  return coarsest;
}

std::vector<Index> ActiveCut::level_counts() const {
  std::vector<Index> counts(static_cast<std::size_t>(m_tree->max_level()) + 1, 0);
  for (const NodeId n : m_nodes)
    ++counts[m_tree->level(n)];
  return counts;
}

NodeId ActiveCut::refine(NodeId n) {
  STRATA_VERIFY(is_active(n), "ActiveCut::refine: node is not active");
  STRATA_VERIFY(m_tree->can_refine(n), "ActiveCut::refine: node is at the maximum level");
  const NodeId first = m_tree->refine(n);
  deactivate(n);
  for (int k = 0; k < 8; ++k)
    activate(first + k);
  return first;
}

bool ActiveCut::can_coarsen(NodeId parent) const {
  if (!m_tree->is_alive(parent) || m_tree->is_leaf(parent)) return false;
  const NodeId first = m_tree->child(parent, 0);
  for (int k = 0; k < 8; ++k)
    if (!is_active(first + k)) return false;
  return true;
}

void ActiveCut::coarsen(NodeId parent, bool release_nodes) {
  STRATA_VERIFY(can_coarsen(parent), "ActiveCut::coarsen: the eight children are not all active");
  const NodeId first = m_tree->child(parent, 0);
  for (int k = 0; k < 8; ++k)
    deactivate(first + k);
  activate(parent);
  if (release_nodes) m_tree->coarsen_subtree(parent);
}

void ActiveCut::validate() const {
  const TetTree& tree = *m_tree;
  const int max_level = tree.max_level();
  // Exact coverage count per root: a node at level l covers 8^(max_level − l) finest cells
  // (≤ 8^20 = 2^60, so sums per root fit in 64 bits).
  std::vector<std::uint64_t> covered(static_cast<std::size_t>(tree.num_roots()), 0);
  for (std::size_t i = 0; i < m_nodes.size(); ++i) {
    const NodeId n = m_nodes[i];
    if (!tree.is_alive(n))
      throw InputError("ActiveCut: active node " + std::to_string(n) + " is not a live tree node");
    if (m_slot[n] != static_cast<int>(i))
      throw InputError("ActiveCut: node " + std::to_string(n) + " is listed twice");
    for (NodeId a = tree.parent(n); a != kNoNode; a = tree.parent(a))
      if (is_active(a))
        throw InputError("ActiveCut: node " + std::to_string(n) + " and its ancestor " +
                         std::to_string(a) + " are both active");
    covered[tree.node(n).root] += std::uint64_t{1} << (3 * (max_level - tree.level(n)));
  }
  const std::uint64_t full = std::uint64_t{1} << (3 * max_level);
  for (std::size_t r = 0; r < covered.size(); ++r)
    if (covered[r] != full)
      throw InputError("ActiveCut: the active nodes do not cover root " + std::to_string(r) +
                       " exactly (a gap below it)");
}

void ActiveCut::activate(NodeId n) {
  if (static_cast<std::size_t>(n) >= m_slot.size())
    m_slot.resize(
        std::max(static_cast<std::size_t>(m_tree->pool_size()), static_cast<std::size_t>(n) + 1),
        -1);
  m_slot[n] = static_cast<int>(m_nodes.size());
  m_nodes.push_back(n);
}

void ActiveCut::deactivate(NodeId n) {
  const int slot = m_slot[n];
  const NodeId last = m_nodes.back();
  m_nodes[slot] = last;
  m_slot[last] = slot;
  m_nodes.pop_back();
  m_slot[n] = -1;
}

}  // namespace strata
