#include "strata/core/common/vector_chunks.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

Index num_chunks(Index n) {
  return (n + kVectorChunk - 1) / kVectorChunk;
}

}  // namespace

void for_each_vector_chunk(Index n, const std::function<void(Index, Index)>& f) {
  const Index chunks = num_chunks(n);
  if (chunks <= 1) {
    if (n > 0) f(0, n);
    return;
  }
  tbb::parallel_for(Index(0), chunks,
                    [&](Index k) { f(k * kVectorChunk, std::min(n, (k + 1) * kVectorChunk)); });
}

double sum_over_vector_chunks(Index n, const std::function<double(Index, Index)>& f) {
  const Index chunks = num_chunks(n);
  if (chunks <= 1) return n > 0 ? f(0, n) : 0.0;
  std::vector<double> partial(static_cast<std::size_t>(chunks));
  tbb::parallel_for(Index(0), chunks, [&](Index k) {
    partial[k] = f(k * kVectorChunk, std::min(n, (k + 1) * kVectorChunk));
  });
  double sum = 0.0;
  for (const double value : partial)
    sum += value;
  return sum;
}

double chunked_dot(ConstRef<VectorXd> a, ConstRef<VectorXd> b) {
  STRATA_VERIFY(a.size() == b.size(), "chunked_dot: sizes differ");
  return sum_over_vector_chunks(a.size(), [&](Index begin, Index end) {
    return a.segment(begin, end - begin).dot(b.segment(begin, end - begin));
  });
}

}  // namespace strata
