#include "strata/core/common/compressed_lists.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <string>

#include "strata/core/common/error.hpp"

namespace strata {

CompressedLists sorted_unique_lists(Index n, Index universe,
                                    const std::function<void(Index, std::vector<int>&)>& gather) {
  STRATA_VERIFY(n >= 0 && universe >= 0, "sorted_unique_lists: negative size");
  STRATA_VERIFY(n <= std::numeric_limits<int>::max(), "sorted_unique_lists: too many lists");
  CompressedLists lists;
  lists.offsets.assign(n + 1, 0);
  if (n == 0) return lists;
  // Fixed chunks, each collecting its lists in a buffer of its own; then one copy into place.
  const Index num_chunks = std::min<Index>(n, 256);
  std::vector<std::vector<int>> chunk_indices(num_chunks);
  // Per thread, the list that last saw each entry: duplicates go before the (short) sort.
  tbb::enumerable_thread_specific<std::vector<int>> last_seen(
      [&] { return std::vector<int>(universe, -1); });
  tbb::parallel_for(Index(0), num_chunks, [&](Index c) {
    const Index begin = n * c / num_chunks, end = n * (c + 1) / num_chunks;
    std::vector<int>& seen = last_seen.local();
    std::vector<int> buffer;
    std::vector<int>& out = chunk_indices[c];
    for (Index i = begin; i < end; ++i) {
      buffer.clear();
      gather(i, buffer);
      const auto first = out.size();
      for (const int entry : buffer) {
        STRATA_VERIFY(entry >= 0 && entry < universe, "sorted_unique_lists: entry out of range");
        if (seen[entry] == static_cast<int>(i)) continue;
        seen[entry] = static_cast<int>(i);
        out.push_back(entry);
      }
      std::sort(out.begin() + first, out.end());
      lists.offsets[i + 1] = static_cast<Index>(out.size() - first);
    }
  });
  join_chunk_lists(lists, chunk_indices);
  return lists;
}

void join_chunk_lists(CompressedLists& lists, const std::vector<std::vector<int>>& chunk_indices) {
  const Index n = lists.size();
  const auto num_chunks = static_cast<Index>(chunk_indices.size());
  for (Index i = 0; i < n; ++i)
    lists.offsets[i + 1] += lists.offsets[i];
  lists.indices.resize(lists.offsets[n]);
  tbb::parallel_for(Index(0), num_chunks, [&](Index c) {
    const std::vector<int>& chunk = chunk_indices[c];
    std::copy(chunk.begin(), chunk.end(),
              lists.indices.begin() + lists.offsets[n * c / num_chunks]);
  });
}

CompressedLists transpose_lists(const CompressedLists& lists, Index num_targets) {
  STRATA_VERIFY(num_targets >= 0, "transpose_lists: negative number of targets");
  CompressedLists result;
  result.offsets.assign(num_targets + 1, 0);
  for (const int j : lists.indices) {
    STRATA_VERIFY(j >= 0 && j < num_targets, "transpose_lists: entry out of range");
    ++result.offsets[j + 1];
  }
  for (Index j = 0; j < num_targets; ++j)
    result.offsets[j + 1] += result.offsets[j];
  result.indices.resize(lists.indices.size());
  std::vector<Index> next(result.offsets.begin(), result.offsets.end() - 1);
  for (Index i = 0; i < lists.size(); ++i)
    for (const int j : lists[i])
      result.indices[next[j]++] = static_cast<int>(i);
  return result;
}

SparseMatrixd block_pattern(const CompressedLists& block_rows, const std::string& what) {
  const Index n = block_rows.size();
  const Index nnz = 9 * static_cast<Index>(block_rows.indices.size());
  if (nnz > std::numeric_limits<int>::max()) throw InputError(what + " exceeds 2^31 entries");
  SparseMatrixd pattern(3 * n, 3 * n);
  pattern.resizeNonZeros(nnz);
  int* outer = pattern.outerIndexPtr();
  int* inner = pattern.innerIndexPtr();
  double* values = pattern.valuePtr();
  outer[3 * n] = static_cast<int>(nnz);
  tbb::parallel_for(Index(0), n, [&](Index b) {
    for (int j = 0; j < 3; ++j) {
      const Index start = block_column_start(block_rows, b, j);
      Index position = outer[3 * b + j] = static_cast<int>(start);
      for (const int a : block_rows[b])
        for (int i = 0; i < 3; ++i)
          inner[position++] = 3 * a + i;
      std::fill(values + start, values + position, 0.0);
    }
  });
  return pattern;
}

}  // namespace strata
