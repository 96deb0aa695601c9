#include "strata/hierarchy/cut_levels.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace strata {

namespace {

/// Merges spaces that shrink too little: keeps the finest, then each coarser space at most 0.7
/// times the size of the last one kept.
NestedSpaces merge_weak_levels(const NestedSpaces& spaces) {
  NestedSpaces merged;
  const int finest = spaces.num_levels() - 1;
  if (finest < 1) return merged;
  // P and injection map space k onto the last kept space.
  SparseMatrixd P = spaces.prolongations[finest - 1];
  std::vector<Index> injection = spaces.injections[finest - 1];
  double kept_size = static_cast<double>(spaces.num_fine_vertices());
  for (int k = finest - 1; k >= 0; --k) {
    const auto size = static_cast<double>(spaces.injections[k].size());
    if (size <= 0.7 * kept_size) {
      merged.prolongations.push_back(P);
      merged.injections.push_back(injection);
      if (!spaces.keys.empty()) merged.keys.push_back(spaces.keys[k]);
      kept_size = size;
      if (k > 0) {
        P = spaces.prolongations[k - 1];
        injection = spaces.injections[k - 1];
      }
    } else if (k > 0) {
      P = SparseMatrixd(P * spaces.prolongations[k - 1]);
      std::vector<Index> composed(spaces.injections[k - 1].size());
      for (std::size_t j = 0; j < composed.size(); ++j)
        composed[j] = injection[spaces.injections[k - 1][j]];
      injection = std::move(composed);
    }
  }
  std::reverse(merged.prolongations.begin(), merged.prolongations.end());
  std::reverse(merged.injections.begin(), merged.injections.end());
  std::reverse(merged.keys.begin(), merged.keys.end());
  return merged;
}

}  // namespace

NestedSpaces cut_nested_spaces(const TetTree& tree, const ConstrainedCut& cut) {
  const FlatTreeMesh& flat = cut.flat;
  const HangingConstraints& constraints = cut.constraints;
  const std::vector<int>& free_vertices = constraints.free_vertices();
  const Index num_free = static_cast<Index>(free_vertices.size());
  std::vector<int> level(num_free);
  int finest = 0;
  for (Index q = 0; q < num_free; ++q) {
    level[q] = tree.vertex_level(flat.tree_vertices[free_vertices[q]]);
    finest = std::max(finest, level[q]);
  }
  NestedSpaces spaces;
  if (finest == 0) return spaces;

  // index[k][q]: position of free vertex q in space k (−1 if its level exceeds k).
  std::vector<std::vector<Index>> index(finest + 1, std::vector<Index>(num_free, -1));
  std::vector<Index> sizes(finest + 1, 0);
  for (int k = 0; k <= finest; ++k)
    for (Index q = 0; q < num_free; ++q)
      if (level[q] <= k) index[k][q] = sizes[k]++;

  const Eigen::SparseMatrix<double, Eigen::RowMajor> C = constraints.matrix();
  for (int k = 0; k < finest; ++k) {
    std::vector<Eigen::Triplet<double>> triplets;
    std::vector<Index> injection(sizes[k], -1);
    for (Index q = 0; q < num_free; ++q) {
      const Index row = index[k + 1][q];
      if (row < 0) continue;
      if (level[q] <= k) {
        triplets.emplace_back(row, index[k][q], 1.0);
        injection[index[k][q]] = row;
        continue;
      }
      for (const int parent : tree.vertex_parents(flat.tree_vertices[free_vertices[q]])) {
        const int mesh_vertex = flat.mesh_vertices[parent];
        if (mesh_vertex < 0)
          throw std::logic_error("cut_nested_spaces: parent vertex " + std::to_string(parent) +
                                 " is not in the flattened cut");
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(C, mesh_vertex); it;
             ++it) {
          const Index col = index[k][it.col()];
          if (col < 0)
            throw std::logic_error("cut_nested_spaces: vertex " + std::to_string(parent) +
                                   " depends on a vertex finer than level " + std::to_string(k));
          triplets.emplace_back(row, col, 0.5 * it.value());
        }
      }
    }
    SparseMatrixd P(sizes[k + 1], sizes[k]);
    P.setFromTriplets(triplets.begin(), triplets.end());
    spaces.prolongations.push_back(std::move(P));
    spaces.injections.push_back(std::move(injection));
    // The tree vertices of space k: what the next cut's space k is compared with.
    std::vector<std::int64_t>& keys = spaces.keys.emplace_back(sizes[k]);
    for (Index q = 0; q < num_free; ++q)
      if (index[k][q] >= 0) keys[index[k][q]] = flat.tree_vertices[free_vertices[q]];
  }
  return merge_weak_levels(spaces);
}

}  // namespace strata
