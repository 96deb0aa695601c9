#pragma once
/// \file tet_partition.hpp
/// A race-free, deterministic parallel schedule for element loops that scatter into shared
/// vertices: tets are sorted along a Morton curve, cut into contiguous chunks, and the chunks are
/// coloured so that no two chunks of one colour share a vertex. Colours run one after another,
/// chunks of a colour in parallel, tets of a chunk in order; so every vertex receives its
/// contributions in the same order whatever the thread count (bitwise-reproducible sums).
#include <functional>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct TetPartition {
  /// order[i] = original index of the tet at position i of the sorted sequence.
  std::vector<int> order;
  /// Chunk c covers sorted positions [chunk_begin[c], chunk_begin[c+1]); every chunk begins at a
  /// multiple of 8.
  std::vector<int> chunk_begin;
  /// Chunk indices of each colour; chunks of one colour share no vertex.
  std::vector<std::vector<int>> colors;

  Index num_chunks() const { return static_cast<Index>(chunk_begin.size()) - 1; }
};

/// Builds the schedule. `target_chunks` bounds the number of chunks (more chunks: better balance,
/// more colours). Vertex indices out of range are skipped and non-finite coordinates sort first
/// (the rest data, compute_tet_rest_data, reports both).
TetPartition build_tet_partition(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 int target_chunks = 256);

/// Runs body(chunk) for every chunk: colours in sequence, chunks of a colour in parallel (TBB).
void for_each_chunk_colored(const TetPartition& partition, const std::function<void(int)>& body);

}  // namespace strata
