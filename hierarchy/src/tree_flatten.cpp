#include "strata/hierarchy/tree_flatten.hpp"

#include "strata/core/common/error.hpp"

namespace strata {

FlatTreeMesh flatten_nodes(const TetTree& tree, const std::vector<NodeId>& nodes,
                           VertexNumbering numbering) {
  FlatTreeMesh flat;
  flat.tet_nodes = nodes;
  flat.mesh_vertices.assign(static_cast<std::size_t>(tree.vertex_capacity()), -1);
  int count = 0;
  for (const NodeId n : nodes) {
    STRATA_VERIFY(tree.is_alive(n), "flatten_nodes: node is not alive");
    for (const int v : tree.tet_vertices(n))
      if (flat.mesh_vertices[v] < 0) flat.mesh_vertices[v] = count++;
  }
  if (numbering == VertexNumbering::tree_id) {
    count = 0;
    for (int& mesh_vertex : flat.mesh_vertices)
      if (mesh_vertex >= 0) mesh_vertex = count++;
  }

  flat.tree_vertices.resize(count);
  flat.mesh.vertices.resize(count, 3);
  for (std::size_t v = 0; v < flat.mesh_vertices.size(); ++v) {
    const int mesh_vertex = flat.mesh_vertices[v];
    if (mesh_vertex < 0) continue;
    flat.tree_vertices[mesh_vertex] = static_cast<int>(v);
    flat.mesh.vertices.row(mesh_vertex) = tree.vertex_position(static_cast<int>(v)).transpose();
  }

  flat.mesh.tets.resize(static_cast<Index>(nodes.size()), 4);
  for (std::size_t t = 0; t < nodes.size(); ++t) {
    const std::array<int, 4> vertices = tree.tet_vertices(nodes[t]);
    for (int i = 0; i < 4; ++i)
      flat.mesh.tets(static_cast<Index>(t), i) = flat.mesh_vertices[vertices[i]];
  }
  return flat;
}

FlatTreeMesh flatten_leaves(const TetTree& tree) {
  return flatten_nodes(tree, tree.leaves());
}

}  // namespace strata
