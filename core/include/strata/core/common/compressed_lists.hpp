#pragma once
/// \file compressed_lists.hpp
/// Many short integer lists stored back to back (the layout of a compressed sparse column
/// pattern): list i holds `indices[offsets[i] .. offsets[i + 1])`.
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct CompressedLists {
  std::vector<Index> offsets{0};  ///< size() + 1 entries, offsets[0] = 0
  std::vector<int> indices;

  Index size() const { return static_cast<Index>(offsets.size()) - 1; }
  Index list_size(Index i) const { return offsets[i + 1] - offsets[i]; }
  std::span<const int> operator[](Index i) const {
    return {indices.data() + offsets[i], static_cast<std::size_t>(list_size(i))};
  }
};

/// Lists 0 … n − 1, list i being what `gather(i, buffer)` appends to an empty buffer, sorted
/// ascending with duplicates removed; every entry must lie in [0, universe). `gather` runs in
/// parallel on strata's threads (it must be safe to call concurrently for different i); the
/// result does not depend on the thread count.
CompressedLists sorted_unique_lists(Index n, Index universe,
                                    const std::function<void(Index, std::vector<int>&)>& gather);

/// Completes lists 0 … n − 1 (n = lists.size()) gathered in C = chunk_indices.size() fixed
/// chunks: on entry lists.offsets[i + 1] holds the length of list i and chunk_indices[c] holds the
/// lists [n c / C, n (c + 1) / C) back to back. Sums the offsets and copies the chunks into place
/// (in parallel).
void join_chunk_lists(CompressedLists& lists, const std::vector<std::vector<int>>& chunk_indices);

/// The transpose of `lists` over `num_targets` targets: list j of the result holds, ascending,
/// every i whose list holds j (as often as it does).
CompressedLists transpose_lists(const CompressedLists& lists, Index num_targets);

/// The 3 × 3-block sparsity of `block_rows` (list b: the block rows of block column b,
/// ascending) as a compressed 3n × 3n matrix of zeros: column 3b + j holds the rows 3a, 3a + 1,
/// 3a + 2 of each a in list b. Built in parallel. Throws InputError("<what> exceeds 2^31
/// entries") when the matrix would not fit Eigen's int indices.
SparseMatrixd block_pattern(const CompressedLists& block_rows, const std::string& what);

/// The value index of the first entry of column 3b + j in block_pattern(block_rows).
inline Index block_column_start(const CompressedLists& block_rows, Index b, int j) {
  return 9 * block_rows.offsets[b] + 3 * j * block_rows.list_size(b);
}

}  // namespace strata
