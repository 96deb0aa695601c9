#pragma once
/// \file tet_tree.hpp
/// The refinement tree: every tet of a coarse mesh roots a tree of nested tets, each node
/// red-refined (1:8, Bey's rule, red_refinement.hpp) on demand up to a maximum level.
///
/// Storage (MFEM ncmesh / OpenVDB style, no per-node heap objects):
/// - one node pool, `TetNode` records of 32 bytes; roots are nodes 0..#roots−1 (node r = coarse tet
///   r); the eight children of a node are created together in one block of eight consecutive ids,
///   so `child(n, k) = first_child(n) + k`. Coarsening puts the block on a free list and the next
///   refinement reuses it;
/// - one vertex array (rest positions), growing as refinement creates edge midpoints. A midpoint
///   records its two parent vertices (x_m = ½(x_a + x_b)), found through `EdgeMidpointMap`, so
///   neighbours share it;
/// - each vertex counts the live nodes that use it as a corner. When coarsening drops the count of
///   a midpoint to zero (no neighbour still refines that edge), the vertex is freed, its id goes
///   to a vertex free list and its edge-map entry is erased. Coarse vertices are never freed.
///
/// Memory follows the nodes that exist, never anything per potential node: the roots and coarse
/// vertices are stored exactly; beyond them each created node costs 32 bytes and each midpoint
/// ~37 bytes plus 16–64 bytes of hash table (at most half full). The arrays grow by the size of
/// their refined part (at least 1024 entries), so the slack is at most that part plus 1024. Ids of
/// live nodes and vertices are stable under refinement and coarsening elsewhere.
///
/// Lifecycle of an adaptive step (later parts build on this class):
///   mark (choose nodes) → refine / coarsen (this class) → rebuild hanging-vertex constraints
///   (from `vertex_parents` of vertices hanging on coarser neighbours) → flatten the active nodes
///   (tree_flatten.hpp) → simulate on the flat TetMesh.
/// Not thread-safe for editing; const queries may run concurrently. `refine` may grow the pool:
/// references returned by `node`, `bey_vertices` and `vertex_position` are invalidated by it,
/// ids are not.
///
/// Vertex ids freed by coarsening may be reused by a later refinement: per-vertex simulation
/// state must be re-initialised for vertices a refinement creates (e.g. ½(x_a + x_b) of the
/// deformed parents, in order of `vertex_level`).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/common/types.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/edge_midpoint_map.hpp"
#include "strata/hierarchy/red_refinement.hpp"

namespace strata {

/// Index of a node in the tree's pool.
using NodeId = int;
/// "No node" (parent of a root, first child of a leaf).
inline constexpr NodeId kNoNode = -1;

/// One tree node (32 bytes).
struct TetNode {
  std::array<int, 4> vertices{-1, -1, -1, -1};  ///< vertex ids in Bey order (refinement order)
  NodeId parent = kNoNode;                      ///< kNoNode for roots
  NodeId first_child = kNoNode;                 ///< kNoNode for leaves; children are +0..+7
  int root = -1;                                ///< coarse tet this node descends from
  std::int8_t level = 0;                        ///< 0 for roots
  std::int8_t child_slot = -1;                  ///< k in 0..7 (Bey child T_k), −1 for roots
  std::int8_t orientation = 1;  ///< sign of the volume of the Bey-ordered vertices (±1)
  std::int8_t alive = 0;        ///< 1 while in use, 0 on the free list
};

class TetTree {
 public:
  /// Deepest level a tree may be built for (levels are stored in 8 bits; 2^20 finer than the
  /// coarse mesh is far beyond any use).
  static constexpr int kMaxSupportedLevel = 20;

  /// Roots = the tets of `coarse` (any orientation; each root's orientation is recorded).
  /// Throws InputError if the mesh is invalid (validate_tet_mesh) or `max_level` is not in
  /// 0..kMaxSupportedLevel.
  TetTree(const TetMesh& coarse, int max_level);

  // --- sizes -----------------------------------------------------------------------------------
  int max_level() const { return m_max_level; }
  Index num_roots() const { return m_num_roots; }
  /// Live nodes (roots included).
  Index num_nodes() const { return m_num_nodes; }
  /// Live nodes without children.
  Index num_leaves() const { return m_num_leaves; }
  /// Node slots in the pool, live or free: num_roots + 8 · (child blocks ever allocated).
  Index pool_size() const { return static_cast<Index>(m_nodes.size()); }
  /// Child blocks on the free list.
  Index num_free_blocks() const { return static_cast<Index>(m_free_blocks.size()); }
  /// Vertices of the coarse mesh: ids 0..num_coarse_vertices()−1, never freed.
  Index num_coarse_vertices() const { return m_num_coarse_vertices; }
  /// Live vertices.
  Index num_vertices() const { return m_num_vertices; }
  /// Vertex ids are < vertex_capacity() (live or free).
  Index vertex_capacity() const { return static_cast<Index>(m_positions.size()); }
  /// Edge midpoints currently recorded (= live vertices created by refinement).
  Index num_midpoints() const { return static_cast<Index>(m_midpoints.size()); }
  /// Bytes held by the pool, the vertex arrays, the free lists and the midpoint map.
  std::size_t memory_bytes() const;

  // --- nodes -----------------------------------------------------------------------------------
  /// The record of node `n` (checked: 0 ≤ n < pool_size()).
  const TetNode& node(NodeId n) const {
    STRATA_VERIFY(n >= 0 && static_cast<std::size_t>(n) < m_nodes.size(), "node id out of range");
    return m_nodes[n];
  }
  bool is_alive(NodeId n) const {
    return n >= 0 && static_cast<std::size_t>(n) < m_nodes.size() && m_nodes[n].alive != 0;
  }
  bool is_leaf(NodeId n) const { return node(n).first_child == kNoNode; }
  int level(NodeId n) const { return node(n).level; }
  NodeId parent(NodeId n) const { return node(n).parent; }
  /// Child k (0..7, Bey's T_k) of `n`, or kNoNode if `n` is a leaf.
  NodeId child(NodeId n, int k) const;
  /// Vertices in Bey order (the order refinement uses; may be negatively oriented).
  const std::array<int, 4>& bey_vertices(NodeId n) const { return node(n).vertices; }
  /// Vertices in a positively oriented order (Bey order, last two swapped when needed): the order
  /// of the tet in a flattened mesh.
  std::array<int, 4> tet_vertices(NodeId n) const {
    const TetNode& record = node(n);
    return oriented_tet(record.vertices, record.orientation);
  }
  /// Rest positions of `tet_vertices(n)` as columns (3 × 4).
  Matrix3x4d tet_positions(NodeId n) const;
  /// Rest positions of `bey_vertices(n)` as columns (3 × 4).
  Matrix3x4d bey_positions(NodeId n) const;
  /// Leaves of the subtree of `n` (n itself if a leaf), depth first in child order.
  std::vector<NodeId> leaves(NodeId n) const;
  /// Leaves of all roots, depth first, root by root.
  std::vector<NodeId> leaves() const;

  // --- vertices --------------------------------------------------------------------------------
  /// Rest position [m] of vertex `v`.
  const Vector3d& vertex_position(int v) const { return m_positions[checked_vertex(v)]; }
  /// The two vertices whose midpoint `v` is, or {−1, −1} for a coarse vertex.
  const std::array<int, 2>& vertex_parents(int v) const { return m_parents[checked_vertex(v)]; }
  /// 0 for coarse vertices, 1 + max(level of the parents) for midpoints.
  int vertex_level(int v) const { return m_vertex_levels[checked_vertex(v)]; }
  /// Whether `v` is in use (coarse, or a midpoint some live node uses).
  bool is_vertex_alive(int v) const;
  /// Live nodes that have `v` as a corner.
  int vertex_use_count(int v) const;
  /// The midpoint vertex of edge {a, b}, or −1 if no live node refines that edge.
  int midpoint(int a, int b) const { return m_midpoints.find(a, b); }

  // --- editing ---------------------------------------------------------------------------------
  /// Whether `n` is a live node below the maximum level.
  bool can_refine(NodeId n) const;
  /// Creates the eight children of `n` (and the edge midpoints not yet shared with a neighbour);
  /// returns the first child. Idempotent: a node with children returns them unchanged.
  /// Checked: `n` is live and below max_level (std::logic_error otherwise).
  NodeId refine(NodeId n);
  /// Whether `n` has children and none of them has children.
  bool can_coarsen(NodeId n) const;
  /// Releases the eight children of `n` to the free list (and frees midpoints no live node uses
  /// any more); returns false if `n` was a leaf already. Checked: no child has children (coarsen
  /// bottom-up, or use `coarsen_subtree`).
  bool coarsen(NodeId n);
  /// Releases every descendant of `n`, deepest first; returns how many nodes were released.
  Index coarsen_subtree(NodeId n);

 private:
  std::size_t checked_vertex(int v) const {
    STRATA_VERIFY(v >= 0 && static_cast<std::size_t>(v) < m_positions.size(),
                  "vertex id out of range");
    return static_cast<std::size_t>(v);
  }
  NodeId allocate_block();
  int midpoint_or_create(int a, int b);
  void release_vertex(int v);

  int m_max_level = 0;
  Index m_num_roots = 0;
  Index m_num_nodes = 0;
  Index m_num_leaves = 0;
  Index m_num_vertices = 0;
  Index m_num_coarse_vertices = 0;
  std::vector<TetNode> m_nodes;
  std::vector<NodeId> m_free_blocks;  ///< first ids of released child blocks (LIFO)
  std::vector<Vector3d> m_positions;
  std::vector<std::array<int, 2>> m_parents;
  std::vector<int> m_use_counts;  ///< −1 marks a free vertex id
  std::vector<std::int8_t> m_vertex_levels;
  std::vector<int> m_free_vertices;  ///< released midpoint ids (LIFO)
  EdgeMidpointMap m_midpoints;
};

}  // namespace strata
