#include "strata/hierarchy/tet_tree.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/red_refinement.hpp"

namespace strata {
namespace {

// Makes room for `extra` more elements. Growth is proportional to the part beyond the first
// `fixed` elements (the roots / coarse vertices, sized exactly at construction), at least
// kMinGrowth: refining a few nodes of a large coarse mesh does not double the coarse storage.
constexpr std::size_t kMinGrowth = 1024;

template <typename T>
void reserve_more(std::vector<T>& array, std::size_t fixed, std::size_t extra) {
  if (array.size() + extra <= array.capacity()) return;
  array.reserve(array.size() + std::max({extra, kMinGrowth, array.size() - fixed}));
}

}  // namespace

TetTree::TetTree(const TetMesh& coarse, int max_level) : m_max_level(max_level) {
  if (max_level < 0 || max_level > kMaxSupportedLevel)
    throw InputError("TetTree: max_level " + std::to_string(max_level) + " is not in 0.." +
                     std::to_string(kMaxSupportedLevel));
  validate_tet_mesh(coarse, "coarse mesh");
  if (coarse.vertices.rows() >= std::numeric_limits<int>::max() / 2 ||
      coarse.tets.rows() >= std::numeric_limits<int>::max() / 2)
    throw InputError("TetTree: coarse mesh too large for 32-bit ids");

  const Index num_vertices = coarse.vertices.rows();
  m_positions.reserve(num_vertices);
  for (Index v = 0; v < num_vertices; ++v)
    m_positions.push_back(coarse.vertices.row(v).transpose());
  m_parents.assign(num_vertices, {-1, -1});
  m_use_counts.assign(num_vertices, 0);
  m_vertex_levels.assign(num_vertices, 0);
  m_num_vertices = num_vertices;
  m_num_coarse_vertices = num_vertices;

  m_num_roots = coarse.tets.rows();
  m_nodes.resize(m_num_roots);
  for (Index t = 0; t < m_num_roots; ++t) {
    TetNode& root = m_nodes[t];
    for (int i = 0; i < 4; ++i) {
      root.vertices[i] = coarse.tets(t, i);
      ++m_use_counts[root.vertices[i]];
    }
    root.root = static_cast<int>(t);
    root.alive = 1;
    const auto& x = root.vertices;
    root.orientation = tet_signed_volume(m_positions[x[0]], m_positions[x[1]], m_positions[x[2]],
                                         m_positions[x[3]]) > 0.0
                           ? 1
                           : -1;
  }
  m_num_nodes = m_num_roots;
  m_num_leaves = m_num_roots;
}

std::size_t TetTree::memory_bytes() const {
  return m_nodes.capacity() * sizeof(TetNode) + m_free_blocks.capacity() * sizeof(NodeId) +
         m_positions.capacity() * sizeof(Vector3d) +
         m_parents.capacity() * sizeof(std::array<int, 2>) + m_use_counts.capacity() * sizeof(int) +
         m_vertex_levels.capacity() * sizeof(std::int8_t) +
         m_free_vertices.capacity() * sizeof(int) + m_midpoints.memory_bytes();
}

NodeId TetTree::child(NodeId n, int k) const {
  STRATA_VERIFY(k >= 0 && k < 8, "child slot must be in 0..7");
  const NodeId first = node(n).first_child;
  return first == kNoNode ? kNoNode : first + k;
}

Matrix3x4d TetTree::tet_positions(NodeId n) const {
  const std::array<int, 4> vertices = tet_vertices(n);
  Matrix3x4d x;
  for (int i = 0; i < 4; ++i)
    x.col(i) = m_positions[vertices[i]];
  return x;
}

Matrix3x4d TetTree::bey_positions(NodeId n) const {
  const std::array<int, 4>& vertices = node(n).vertices;
  Matrix3x4d x;
  for (int i = 0; i < 4; ++i)
    x.col(i) = m_positions[vertices[i]];
  return x;
}

std::vector<NodeId> TetTree::leaves(NodeId n) const {
  STRATA_VERIFY(is_alive(n), "leaves: node is not alive");
  std::vector<NodeId> result;
  std::vector<NodeId> stack{n};
  while (!stack.empty()) {
    const NodeId current = stack.back();
    stack.pop_back();
    const NodeId first = m_nodes[current].first_child;
    if (first == kNoNode) {
      result.push_back(current);
      continue;
    }
    for (int k = 7; k >= 0; --k)
      stack.push_back(first + k);
  }
  return result;
}

std::vector<NodeId> TetTree::leaves() const {
  std::vector<NodeId> result;
  result.reserve(static_cast<std::size_t>(m_num_leaves));
  for (NodeId r = 0; r < m_num_roots; ++r) {
    const std::vector<NodeId> subtree = leaves(r);
    result.insert(result.end(), subtree.begin(), subtree.end());
  }
  return result;
}

bool TetTree::is_vertex_alive(int v) const {
  return v >= 0 && static_cast<std::size_t>(v) < m_positions.size() && m_use_counts[v] >= 0;
}

int TetTree::vertex_use_count(int v) const {
  return std::max(0, m_use_counts[checked_vertex(v)]);
}

bool TetTree::can_refine(NodeId n) const {
  return is_alive(n) && m_nodes[n].level < m_max_level;
}

NodeId TetTree::allocate_block() {
  if (!m_free_blocks.empty()) {
    const NodeId first = m_free_blocks.back();
    m_free_blocks.pop_back();
    return first;
  }
  STRATA_VERIFY(m_nodes.size() + 8 <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
                "node pool exceeds 32-bit ids");
  const auto first = static_cast<NodeId>(m_nodes.size());
  reserve_more(m_nodes, static_cast<std::size_t>(m_num_roots), 8);
  m_nodes.resize(m_nodes.size() + 8);
  return first;
}

int TetTree::midpoint_or_create(int a, int b) {
  const int existing = m_midpoints.find(a, b);
  if (existing >= 0) return existing;
  int v;
  if (!m_free_vertices.empty()) {
    v = m_free_vertices.back();
    m_free_vertices.pop_back();
  } else {
    STRATA_VERIFY(m_positions.size() < static_cast<std::size_t>(std::numeric_limits<int>::max()),
                  "vertex array exceeds 32-bit ids");
    v = static_cast<int>(m_positions.size());
    const auto fixed = static_cast<std::size_t>(m_num_coarse_vertices);
    reserve_more(m_positions, fixed, 1);
    reserve_more(m_parents, fixed, 1);
    reserve_more(m_use_counts, fixed, 1);
    reserve_more(m_vertex_levels, fixed, 1);
    m_positions.emplace_back();
    m_parents.emplace_back();
    m_use_counts.push_back(0);
    m_vertex_levels.push_back(0);
  }
  m_positions[v] = 0.5 * (m_positions[a] + m_positions[b]);
  m_parents[v] = {a, b};
  m_use_counts[v] = 0;
  m_vertex_levels[v] =
      static_cast<std::int8_t>(1 + std::max(m_vertex_levels[a], m_vertex_levels[b]));
  m_midpoints.insert(a, b, v);
  ++m_num_vertices;
  return v;
}

NodeId TetTree::refine(NodeId n) {
  STRATA_VERIFY(is_alive(n), "refine: node is not alive");
  if (m_nodes[n].first_child != kNoNode) return m_nodes[n].first_child;
  STRATA_VERIFY(m_nodes[n].level < m_max_level, "refine: node is at the maximum level");

  // Copy what is needed: allocate_block may reallocate the pool.
  const TetNode parent = m_nodes[n];
  std::array<int, 10> points;
  for (int i = 0; i < 4; ++i)
    points[i] = parent.vertices[i];
  for (int e = 0; e < 6; ++e)
    points[4 + e] =
        midpoint_or_create(parent.vertices[kTetEdges[e][0]], parent.vertices[kTetEdges[e][1]]);

  const NodeId first = allocate_block();
  for (int k = 0; k < 8; ++k) {
    TetNode& child = m_nodes[first + k];
    for (int i = 0; i < 4; ++i) {
      child.vertices[i] = points[kBeyChildren[k][i]];
      ++m_use_counts[child.vertices[i]];
    }
    child.parent = n;
    child.first_child = kNoNode;
    child.root = parent.root;
    child.level = static_cast<std::int8_t>(parent.level + 1);
    child.child_slot = static_cast<std::int8_t>(k);
    child.orientation = static_cast<std::int8_t>(parent.orientation * kBeyChildOrientation[k]);
    child.alive = 1;
  }
  m_nodes[n].first_child = first;
  m_num_nodes += 8;
  m_num_leaves += 7;
  return first;
}

bool TetTree::can_coarsen(NodeId n) const {
  if (!is_alive(n) || m_nodes[n].first_child == kNoNode) return false;
  const NodeId first = m_nodes[n].first_child;
  for (int k = 0; k < 8; ++k)
    if (m_nodes[first + k].first_child != kNoNode) return false;
  return true;
}

void TetTree::release_vertex(int v) {
  if (--m_use_counts[v] > 0 || m_parents[v][0] < 0) return;
  m_midpoints.erase(m_parents[v][0], m_parents[v][1]);
  m_use_counts[v] = -1;
  m_parents[v] = {-1, -1};
  m_positions[v].setConstant(std::numeric_limits<double>::quiet_NaN());
  m_free_vertices.push_back(v);
  --m_num_vertices;
}

bool TetTree::coarsen(NodeId n) {
  STRATA_VERIFY(is_alive(n), "coarsen: node is not alive");
  const NodeId first = m_nodes[n].first_child;
  if (first == kNoNode) return false;
  for (int k = 0; k < 8; ++k)
    STRATA_VERIFY(m_nodes[first + k].first_child == kNoNode,
                  "coarsen: a child has children (coarsen bottom-up or use coarsen_subtree)");
  for (int k = 0; k < 8; ++k) {
    TetNode& child = m_nodes[first + k];
    for (int i = 0; i < 4; ++i)
      release_vertex(child.vertices[i]);
    child = TetNode{};
  }
  m_free_blocks.push_back(first);
  m_nodes[n].first_child = kNoNode;
  m_num_nodes -= 8;
  m_num_leaves -= 7;
  return true;
}

Index TetTree::coarsen_subtree(NodeId n) {
  STRATA_VERIFY(is_alive(n), "coarsen_subtree: node is not alive");
  if (m_nodes[n].first_child == kNoNode) return 0;
  Index released = 0;
  const NodeId first = m_nodes[n].first_child;
  for (int k = 0; k < 8; ++k)
    released += coarsen_subtree(first + k);
  coarsen(n);
  return released + 8;
}

}  // namespace strata
