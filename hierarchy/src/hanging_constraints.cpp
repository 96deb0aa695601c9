#include "strata/hierarchy/hanging_constraints.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <utility>

#include "strata/core/common/error.hpp"
#include "strata/hierarchy/red_refinement.hpp"

namespace strata {
namespace {

constexpr std::array<std::array<int, 3>, 4> kTetFaces = {
    {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};

// P = C ⊗ I₃ in the vertex-major DOF layout.
SparseMatrixd kronecker_identity3(const SparseMatrixd& C) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(3 * static_cast<std::size_t>(C.nonZeros()));
  for (Index q = 0; q < C.outerSize(); ++q)
    for (SparseMatrixd::InnerIterator it(C, q); it; ++it)
      for (int c = 0; c < 3; ++c)
        triplets.emplace_back(static_cast<int>(3 * it.row() + c), static_cast<int>(3 * q + c),
                              it.value());
  SparseMatrixd P(3 * C.rows(), 3 * C.cols());
  P.setFromTriplets(triplets.begin(), triplets.end());
  return P;
}

// Walks the mesh vertices on the boundary of one active tet (not its corners) and records each
// as (mesh vertex, tet's node), in walk order.
class BoundaryWalker {
 public:
  using Record = std::pair<int, NodeId>;
  BoundaryWalker(const TetTree& tree, const FlatTreeMesh& flat, std::vector<Record>& records)
      : m_tree(tree), m_mesh_vertices(flat.mesh_vertices), m_records(records) {}

  void walk(NodeId node) {
    // A tet at the tree's deepest level has no edge midpoints: nothing lies on its boundary.
    if (m_tree.level(node) >= m_tree.max_level()) return;
    m_node = node;
    const std::array<int, 4>& v = m_tree.bey_vertices(node);
    // Each edge's midpoint is looked up once; the faces' walks start from them.
    std::array<int, 6> mid{};
    bool any = false;
    for (int e = 0; e < 6; ++e) {
      mid[e] = m_tree.midpoint(v[kTetEdges[e][0]], v[kTetEdges[e][1]]);
      any = any || is_mesh_vertex(mid[e]);
    }
    if (!any) return;  // no mesh vertex on an edge, hence none inside a face
    for (int e = 0; e < 6; ++e)
      walk_edge(v[kTetEdges[e][0]], v[kTetEdges[e][1]], mid[e]);
    for (const auto& f : kTetFaces)
      walk_face_interior(v[f[0]], v[f[1]], v[f[2]], mid[edge_index(f[0], f[1])],
                         mid[edge_index(f[0], f[2])], mid[edge_index(f[1], f[2])]);
  }

 private:
  // The position of the tet edge {i, j} (i < j) in kTetEdges.
  static constexpr int edge_index(int i, int j) { return i == 0 ? j - 1 : i + j; }

  // Mesh vertices on the open segment a–b: its midpoint and, recursively, those of the halves.
  // A mesh vertex's parents are mesh vertices, so the walk stops at a midpoint outside the mesh.
  void walk_edge(int a, int b) { walk_edge(a, b, m_tree.midpoint(a, b)); }
  void walk_edge(int a, int b, int m) {
    if (!is_mesh_vertex(m)) return;
    record(m);
    walk_edge(a, m);
    walk_edge(m, b);
  }

  // Mesh vertices inside the triangle a, b, c (not on its edges). The face was refined iff all
  // three edge midpoints exist; every vertex inside descends (through parents) from one of them,
  // so the walk stops when none of them is a mesh vertex.
  void walk_face_interior(int a, int b, int c) {
    walk_face_interior(a, b, c, m_tree.midpoint(a, b), m_tree.midpoint(a, c),
                       m_tree.midpoint(b, c));
  }
  void walk_face_interior(int a, int b, int c, int ab, int ac, int bc) {
    if (ab < 0 || ac < 0 || bc < 0) return;
    if (!is_mesh_vertex(ab) && !is_mesh_vertex(ac) && !is_mesh_vertex(bc)) return;
    walk_edge(ab, ac);
    walk_edge(ab, bc);
    walk_edge(ac, bc);
    walk_face_interior(a, ab, ac);
    walk_face_interior(b, ab, bc);
    walk_face_interior(c, ac, bc);
    walk_face_interior(ab, ac, bc);
  }

  bool is_mesh_vertex(int tree_vertex) const {
    return tree_vertex >= 0 && static_cast<std::size_t>(tree_vertex) < m_mesh_vertices.size() &&
           m_mesh_vertices[tree_vertex] >= 0;
  }

  void record(int tree_vertex) { m_records.emplace_back(m_mesh_vertices[tree_vertex], m_node); }

  const TetTree& m_tree;
  const std::vector<int>& m_mesh_vertices;
  std::vector<Record>& m_records;
  NodeId m_node = kNoNode;
};

}  // namespace

std::vector<HangingVertex> find_hanging_vertices(const TetTree& tree, const FlatTreeMesh& flat) {
  const auto num_vertices = static_cast<std::size_t>(flat.mesh.vertices.rows());
  STRATA_VERIFY(flat.tree_vertices.size() == num_vertices,
                "find_hanging_vertices: flat mesh and its vertex map disagree");
  // A mesh vertex on the boundary of a tet T of level l (not a corner) lies inside an edge or a
  // face that T shares with a refined tet U of level l (the level-l tets are conforming). The
  // corner children of U keep U's corners, so the active descendants of U include, at each corner
  // of that edge or face, a tet finer than T with that corner. So a tet none of whose corners
  // belongs to a finer active tet has no mesh vertex on its boundary, and only the others are
  // walked.
  const auto num_tets = static_cast<Index>(flat.tet_nodes.size());
  STRATA_VERIFY(flat.tet_levels.size() == flat.tet_nodes.size(),
                "find_hanging_vertices: flat mesh without tet levels");
  std::vector<std::int8_t> finest_level(num_vertices, 0);
  for (Index t = 0; t < num_tets; ++t) {
    const std::int8_t level = flat.tet_levels[t];
    for (int k = 0; k < 4; ++k) {
      std::int8_t& finest = finest_level[flat.mesh.tets(t, k)];
      finest = std::max(finest, level);
    }
  }
  const auto touches_finer = [&](Index t) {
    const std::int8_t level = flat.tet_levels[t];
    for (int k = 0; k < 4; ++k)
      if (finest_level[flat.mesh.tets(t, k)] > level) return true;
    return false;
  };
  // Walks in parallel over fixed chunks of tets; a vertex's host is the coarsest tet it lies on,
  // the first in tet order among equals.
  const Index num_chunks = std::clamp<Index>(num_tets / 1024, 1, 256);
  std::vector<std::vector<BoundaryWalker::Record>> records(num_chunks);
  tbb::parallel_for(Index(0), num_chunks, [&](Index c) {
    BoundaryWalker walker(tree, flat, records[c]);
    for (Index t = num_tets * c / num_chunks; t < num_tets * (c + 1) / num_chunks; ++t)
      if (touches_finer(t)) walker.walk(flat.tet_nodes[t]);
  });
  std::vector<NodeId> host(num_vertices, kNoNode);
  for (const auto& chunk : records)
    for (const auto& [v, node] : chunk)
      if (host[v] == kNoNode || tree.level(host[v]) > tree.level(node)) host[v] = node;

  std::vector<HangingVertex> hanging;
  for (std::size_t v = 0; v < num_vertices; ++v) {
    if (host[v] == kNoNode) continue;
    const int tree_vertex = flat.tree_vertices[v];
    const std::array<int, 2>& parents = tree.vertex_parents(tree_vertex);
    HangingVertex h;
    h.vertex = static_cast<int>(v);
    for (int i = 0; i < 2; ++i) {
      // A refined node's corners are corners of its active descendants, so parents are in the
      // mesh whenever the cut is valid.
      STRATA_VERIFY(parents[i] >= 0 && flat.mesh_vertices[parents[i]] >= 0,
                    "find_hanging_vertices: a hanging vertex's parent is not in the mesh "
                    "(the nodes are not a valid cut)");
      h.parents[i] = flat.mesh_vertices[parents[i]];
    }
    h.host = host[v];
    h.host_level = tree.level(host[v]);
    hanging.push_back(h);
  }
  std::sort(hanging.begin(), hanging.end(), [&](const HangingVertex& x, const HangingVertex& y) {
    const int lx = tree.vertex_level(flat.tree_vertices[x.vertex]);
    const int ly = tree.vertex_level(flat.tree_vertices[y.vertex]);
    return lx != ly ? lx < ly : x.vertex < y.vertex;
  });
  return hanging;
}

HangingConstraints::HangingConstraints(const TetTree& tree, const FlatTreeMesh& flat)
    : m_hanging(find_hanging_vertices(tree, flat)) {
  const auto num_vertices = static_cast<std::size_t>(flat.mesh.vertices.rows());
  m_free_index.assign(num_vertices, 0);
  for (const HangingVertex& h : m_hanging)
    m_free_index[h.vertex] = -1;
  for (std::size_t v = 0; v < num_vertices; ++v) {
    if (m_free_index[v] < 0) continue;
    m_free_index[v] = static_cast<int>(m_free_vertices.size());
    m_free_vertices.push_back(static_cast<int>(v));
  }

  // Rows of C as sparse (free index, weight) lists, ascending in the free index: a free vertex's
  // row is (q, 1); a hanging vertex's row (kept aside, parents resolved before their children)
  // merges half of each parent's row.
  using Row = std::vector<std::pair<int, double>>;
  std::vector<int> hanging_slot(num_vertices, -1);
  std::vector<Row> hanging_rows(m_hanging.size());
  std::vector<int> depth(m_hanging.size(), 0);
  auto parent_row = [&](int p, Row& free_row) -> const Row& {
    if (m_free_index[p] >= 0) {
      free_row = {{m_free_index[p], 1.0}};
      return free_row;
    }
    STRATA_VERIFY(hanging_slot[p] >= 0, "HangingConstraints: parent resolved after its child");
    return hanging_rows[hanging_slot[p]];
  };
  Row merged, free_row;
  for (std::size_t k = 0; k < m_hanging.size(); ++k) {
    const HangingVertex& h = m_hanging[k];
    merged.clear();
    int parent_depth = 0;
    for (const int p : h.parents) {
      for (const auto& [q, w] : parent_row(p, free_row))
        merged.emplace_back(q, 0.5 * w);
      if (hanging_slot[p] >= 0) parent_depth = std::max(parent_depth, depth[hanging_slot[p]]);
    }
    std::sort(merged.begin(), merged.end());
    Row& row = hanging_rows[k];
    for (const auto& [q, w] : merged) {
      if (!row.empty() && row.back().first == q)
        row.back().second += w;
      else
        row.emplace_back(q, w);
    }
    hanging_slot[h.vertex] = static_cast<int>(k);
    depth[k] = 1 + parent_depth;
    m_max_chain_depth = std::max(m_max_chain_depth, depth[k]);
  }

  // C row by row, then in its column-major storage.
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  RowMajor rows(static_cast<Index>(num_vertices), num_free());
  Index nnz = 0;
  for (std::size_t v = 0; v < num_vertices; ++v) {
    rows.outerIndexPtr()[v] = static_cast<int>(nnz);
    nnz += m_free_index[v] >= 0 ? 1 : static_cast<Index>(hanging_rows[hanging_slot[v]].size());
  }
  rows.outerIndexPtr()[num_vertices] = static_cast<int>(nnz);
  rows.resizeNonZeros(nnz);
  for (std::size_t v = 0; v < num_vertices; ++v) {
    int position = rows.outerIndexPtr()[v];
    if (m_free_index[v] >= 0) {
      rows.innerIndexPtr()[position] = m_free_index[v];
      rows.valuePtr()[position] = 1.0;
      continue;
    }
    for (const auto& [q, w] : hanging_rows[hanging_slot[v]]) {
      rows.innerIndexPtr()[position] = q;
      rows.valuePtr()[position++] = w;
    }
  }
  m_C = rows;
}

SparseMatrixd HangingConstraints::dof_matrix() const {
  return kronecker_identity3(m_C);
}

SparseMatrixd HangingConstraints::reduce_matrix(const SparseMatrixd& K) const {
  STRATA_VERIFY(K.rows() == 3 * num_vertices() && K.cols() == 3 * num_vertices(),
                "HangingConstraints::reduce_matrix: K must be 3·#V square");
  const SparseMatrixd P = dof_matrix();
  return SparseMatrixd(P.transpose() * K * P);
}

VectorXd HangingConstraints::expand(ConstRef<VectorXd> q) const {
  STRATA_VERIFY(q.size() == 3 * num_free(), "HangingConstraints::expand: q must have 3·#Q entries");
  const Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>> Q(q.data(), 3, num_free());
  VectorXd x(3 * num_vertices());
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>> X(x.data(), 3, num_vertices());
  X = Q * m_C.transpose();
  return x;
}

VectorXd HangingConstraints::reduce(ConstRef<VectorXd> f) const {
  STRATA_VERIFY(f.size() == 3 * num_vertices(),
                "HangingConstraints::reduce: f must have 3·#V entries");
  const Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>> F(f.data(), 3, num_vertices());
  VectorXd fq(3 * num_free());
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>> FQ(fq.data(), 3, num_free());
  FQ = F * m_C;
  return fq;
}

VectorXd HangingConstraints::reduce_scalar(ConstRef<VectorXd> s) const {
  STRATA_VERIFY(s.size() == num_vertices(),
                "HangingConstraints::reduce_scalar: s must have #V entries");
  return m_C.transpose() * s;
}

VectorXd HangingConstraints::restrict_to_free(ConstRef<VectorXd> x) const {
  STRATA_VERIFY(x.size() == 3 * num_vertices(),
                "HangingConstraints::restrict_to_free: x must have 3·#V entries");
  VectorXd q(3 * num_free());
  for (std::size_t i = 0; i < m_free_vertices.size(); ++i)
    q.segment<3>(3 * static_cast<Index>(i)) = x.segment<3>(3 * m_free_vertices[i]);
  return q;
}

ConstrainedCut flatten_cut(const ActiveCut& cut) {
  FlatTreeMesh flat =
      flatten_nodes(cut.tree(), cut.depth_first_nodes(), VertexNumbering::first_use);
  HangingConstraints constraints(cut.tree(), flat);
  return {std::move(flat), std::move(constraints)};
}

}  // namespace strata
