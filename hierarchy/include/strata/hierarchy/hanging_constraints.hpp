#pragma once
/// \file hanging_constraints.hpp
/// Hanging-vertex constraints of a flattened active cut, as an embedding x = C q.
///
/// A vertex of the flattened cut is *hanging* if it lies on the boundary (an edge or a face) of an
/// active tet that does not have it as a corner — it was created by refining a neighbour that is
/// finer than that tet. The tree records every refinement vertex v as the midpoint of two parent
/// vertices (a, b) (TetTree::vertex_parents), and the segment a–b lies on the coarser tet, so the
/// conforming position of a hanging vertex is x_v = ½(x_a + x_b). The parents of a vertex of the
/// flattened mesh are themselves vertices of it, and may hang too (a chain: a vertex a quarter of
/// the way along a coarse edge, or inside a coarse face); resolving the rule recursively expresses
/// every hanging vertex through *free* vertices only:
///
///     x = C q,   C: #V × #Q, scalar, applied to each coordinate (x_v = Σ_q C_vq q_q),
///
/// with q the positions of the #Q free vertices. Rows of free vertices are identity rows, all
/// entries are ≥ 0 and every row sums to 1 (a partition of unity: affine fields are reproduced
/// exactly). For the 3·#V vertex-major DOF vectors of core this is C ⊗ I₃ (`dof_matrix`).
///
/// Reduced quantities of the constrained system (so core's integrators and static solver can run on
/// q unchanged): forces f_q = Cᵀ f, stiffness K_q = Pᵀ K P with P = C ⊗ I₃ (`reduce_matrix`),
/// lumped masses m_q = Cᵀ m (= row sums of Cᵀ diag(m) C since C·1 = 1: total mass is kept, no entry
/// negative).
///
/// Detection (`find_hanging_vertices`): for each active tet with a corner that is also a corner of
/// a finer active tet (no other tet can have a mesh vertex on its boundary), walk the tree
/// vertices on its edges
/// (edge midpoints, recursively along the halves) and inside its faces (midpoints of the face's
/// mid-segments, recursively in the four sub-triangles) through TetTree::midpoint; every one that
/// is a vertex of the flattened mesh hangs on that tet. Since the parents of a mesh vertex are mesh
/// vertices, the walk stops where no mesh vertex can follow: the cost is O(#active + #hanging),
/// independent of tree nodes below the cut. Works for any valid cut (no 2:1 balance needed).
#include <array>
#include <vector>

#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

/// One hanging vertex of a flattened cut (mesh vertex ids).
struct HangingVertex {
  int vertex = -1;               ///< the hanging mesh vertex
  std::array<int, 2> parents{};  ///< x_vertex = ½(x_parents[0] + x_parents[1]) (mesh vertices)
  NodeId host = kNoNode;         ///< the coarsest active tet it lies on (not as a corner)
  int host_level = -1;           ///< level of `host`
};

/// All hanging vertices of `flat` (a flattened valid cut of `tree`), ordered so that parents come
/// before the vertices that depend on them (increasing tree vertex level, then mesh vertex).
std::vector<HangingVertex> find_hanging_vertices(const TetTree& tree, const FlatTreeMesh& flat);

/// The embedding x = C q of a flattened cut; built once per cut (rebuild after refine/coarsen).
class HangingConstraints {
 public:
  /// Detects the hanging vertices of `flat` (a flattened valid cut of `tree`) and builds C.
  HangingConstraints(const TetTree& tree, const FlatTreeMesh& flat);

  Index num_vertices() const { return static_cast<Index>(m_free_index.size()); }  ///< #V
  Index num_free() const { return static_cast<Index>(m_free_vertices.size()); }   ///< #Q
  Index num_hanging() const { return static_cast<Index>(m_hanging.size()); }
  bool is_hanging(int v) const { return m_free_index[v] < 0; }
  /// #Q: the mesh vertex of each free vertex (ascending).
  const std::vector<int>& free_vertices() const { return m_free_vertices; }
  /// #V: the free index q of a mesh vertex, or −1 if it hangs.
  const std::vector<int>& free_index() const { return m_free_index; }
  /// The hanging vertices, parents first (see find_hanging_vertices).
  const std::vector<HangingVertex>& hanging() const { return m_hanging; }
  /// Longest chain: 1 if every hanging vertex has free parents, 0 without hanging vertices.
  int max_chain_depth() const { return m_max_chain_depth; }

  /// Scalar C, #V × #Q, column-major.
  const SparseMatrixd& matrix() const { return m_C; }
  /// P = C ⊗ I₃, 3·#V × 3·#Q, for the vertex-major DOF layout (built on each call).
  SparseMatrixd dof_matrix() const;

  /// x = C q per coordinate: 3·#Q → 3·#V (positions, velocities, displacements).
  VectorXd expand(ConstRef<VectorXd> q) const;
  /// f_q = Cᵀ f per coordinate: 3·#V → 3·#Q (forces; energy-consistent since Ψ_q(q) = Ψ(Cq)).
  VectorXd reduce(ConstRef<VectorXd> f) const;
  /// K_q = Pᵀ K P: 3·#V square → 3·#Q square (stiffness, consistent mass, damping).
  SparseMatrixd reduce_matrix(const SparseMatrixd& K) const;
  /// Cᵀ s for one scalar per vertex: #V → #Q (lumped masses).
  VectorXd reduce_scalar(ConstRef<VectorXd> s) const;
  /// The free vertices' entries of a 3·#V vector: 3·#Q (e.g. q from rest positions).
  VectorXd restrict_to_free(ConstRef<VectorXd> x) const;

 private:
  std::vector<int> m_free_vertices;
  std::vector<int> m_free_index;
  std::vector<HangingVertex> m_hanging;
  int m_max_chain_depth = 0;
  SparseMatrixd m_C;
};

/// A flattened cut with its constraints: the simulation mesh (#V vertices, flat.mesh) and x = C q.
struct ConstrainedCut {
  FlatTreeMesh flat;
  HangingConstraints constraints;
};

/// One-shot: the cut's nodes flattened in depth-first order with vertices numbered by first use
/// (`flatten_nodes(cut.tree(), cut.depth_first_nodes(), VertexNumbering::first_use)`: nearby
/// vertices get nearby numbers on every cut), and its HangingConstraints.
ConstrainedCut flatten_cut(const ActiveCut& cut);

}  // namespace strata
