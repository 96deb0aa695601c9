#pragma once

/// \file tree_flatten.hpp
/// Flattening (OpenVDB LeafManager style): a list of tree nodes — the leaves, or any active cut —
/// as a plain TetMesh that core's ElasticModel runs on, with the maps back to the tree.
#include <cstdint>
#include <vector>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/tet_tree.hpp"

namespace strata {

/// A flattened set of tree nodes.
struct FlatTreeMesh {
  /// #V × 3 rest positions and #T × 4 positively oriented tets (tree.tet_vertices order). Only
  /// vertices used by the tets appear, numbered as VertexNumbering says.
  TetMesh mesh;
  std::vector<NodeId> tet_nodes;        ///< #T: the tree node of each tet
  std::vector<std::int8_t> tet_levels;  ///< #T: the tree level of each tet's node
  std::vector<int> tree_vertices;       ///< #V: the tree vertex id of each mesh vertex
  std::vector<int> mesh_vertices;  ///< tree.vertex_capacity(): mesh vertex of a tree vertex, or −1
};

/// How a flattened mesh numbers its vertices.
enum class VertexNumbering {
  /// In increasing tree vertex id: when every coarse vertex is used, coarse vertex i stays vertex
  /// i.
  tree_id,
  /// In the order the tets first use them: with nodes in depth-first order
  /// (ActiveCut::depth_first_nodes) vertices near each other in space get nearby numbers, which
  /// keeps the stiffness matrix's blocks near its diagonal (vertices created by refinement late in
  /// a run have large tree ids wherever they are).
  first_use,
};

/// The given live nodes (in this order) as a mesh. Nodes overlapping each other (a node and its
/// descendant) are not detected; a cut through the tree (each point covered once) gives a valid
/// mesh, conforming if no vertex hangs on a coarser neighbour's edge.
FlatTreeMesh flatten_nodes(const TetTree& tree, const std::vector<NodeId>& nodes,
                           VertexNumbering numbering = VertexNumbering::tree_id);

/// All leaves (tree.leaves() order) as a mesh.
FlatTreeMesh flatten_leaves(const TetTree& tree);

}  // namespace strata
