#include "strata/hierarchy/tree_flatten.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

/// Vertices or tets per parallel task.
constexpr int kChunk = 4096;

}  // namespace

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
  for (std::size_t v = 0; v < flat.mesh_vertices.size(); ++v)
    if (flat.mesh_vertices[v] >= 0) flat.tree_vertices[flat.mesh_vertices[v]] = static_cast<int>(v);
  flat.mesh.vertices.resize(count, 3);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, count, kChunk), [&](const tbb::blocked_range<int>& r) {
        for (int v = r.begin(); v < r.end(); ++v)
          flat.mesh.vertices.row(v) = tree.vertex_position(flat.tree_vertices[v]).transpose();
      });

  const Index num_tets = static_cast<Index>(nodes.size());
  flat.mesh.tets.resize(num_tets, 4);
  flat.tet_levels.resize(nodes.size());
  tbb::parallel_for(tbb::blocked_range<Index>(0, num_tets, kChunk),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index t = r.begin(); t < r.end(); ++t) {
                        const std::array<int, 4> vertices = tree.tet_vertices(nodes[t]);
                        for (int i = 0; i < 4; ++i)
                          flat.mesh.tets(t, i) = flat.mesh_vertices[vertices[i]];
                        flat.tet_levels[t] = static_cast<std::int8_t>(tree.level(nodes[t]));
                      }
                    });
  return flat;
}

FlatTreeMesh flatten_leaves(const TetTree& tree) {
  return flatten_nodes(tree, tree.leaves());
}

}  // namespace strata
