// Vector kernels over fixed chunks (vector_chunks.hpp): every entry visited once, sums added in
// chunk order whatever the thread count, and the dot product against a long-double reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <vector>

#include "strata/core/common/parallel.hpp"
#include "strata/core/common/vector_chunks.hpp"

namespace strata {
namespace {

TEST(VectorChunks, EveryEntryOnceInFixedChunks) {
  for (const Index n : {Index(0), Index(1), kVectorChunk - 1, kVectorChunk, kVectorChunk + 1,
                        5 * kVectorChunk + 17}) {
    std::vector<std::atomic<int>> visits(static_cast<std::size_t>(n));
    std::atomic<int> bad_chunks{0};
    for_each_vector_chunk(n, [&](Index begin, Index end) {
      if (begin % kVectorChunk != 0 || end <= begin || end > n ||
          (end != n && end - begin != kVectorChunk))
        ++bad_chunks;
      for (Index i = begin; i < end; ++i)
        ++visits[i];
    });
    EXPECT_EQ(bad_chunks, 0) << n;
    for (Index i = 0; i < n; ++i)
      ASSERT_EQ(visits[i], 1) << "n " << n << " entry " << i;
  }
}

TEST(VectorChunks, SumsAddTheChunksInOrderAtAnyThreadCount) {
  const Index n = 7 * kVectorChunk + 123;
  const VectorXd a = VectorXd::Random(n), b = VectorXd::Random(n);
  // Each chunk's partial sum by a plain loop, the partial sums added in chunk order by hand.
  const auto partial = [&](Index begin, Index end) {
    double sum = 0.0;
    for (Index i = begin; i < end; ++i)
      sum += a[i] * b[i];
    return sum;
  };
  double expected = 0.0;
  for (Index begin = 0; begin < n; begin += kVectorChunk)
    expected += partial(begin, std::min(n, begin + kVectorChunk));
  double sum_one = 0.0, sum_two = 0.0, dot_one = 0.0, dot_two = 0.0;
  set_thread_policy({.threads = 1});
  sum_one = sum_over_vector_chunks(n, partial);
  dot_one = chunked_dot(a, b);
  set_thread_policy({.threads = 2});
  sum_two = sum_over_vector_chunks(n, partial);
  dot_two = chunked_dot(a, b);
  set_thread_policy({});
  EXPECT_EQ(sum_one, expected);
  EXPECT_EQ(sum_two, expected);
  EXPECT_EQ(dot_one, dot_two);
  long double reference = 0.0L;
  for (Index i = 0; i < n; ++i)
    reference += static_cast<long double>(a[i]) * b[i];
  EXPECT_NEAR(dot_one, static_cast<double>(reference), 1e-12 * a.norm() * b.norm());
  EXPECT_EQ(sum_over_vector_chunks(0, [](Index, Index) { return 1.0; }), 0.0);
  EXPECT_EQ(sum_over_vector_chunks(
                n, [](Index begin, Index end) { return static_cast<double>(end - begin); }),
            static_cast<double>(n));
}

}  // namespace
}  // namespace strata
