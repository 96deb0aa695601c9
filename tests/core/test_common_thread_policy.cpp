// The process-wide thread policy: TBB follows the requested count; the BLAS and OpenMP libraries
// behind CHOLMOD (when loaded) are set to their own count.
#include <gtest/gtest.h>

#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"

namespace strata {
namespace {

TEST(ThreadPolicy, SetsTbbAndBlasThreads) {
  ThreadReport report = set_thread_policy({.threads = 1, .blas_threads = 1});
  EXPECT_EQ(report.threads, 1);
  EXPECT_EQ(max_threads(), 1);
  EXPECT_LE(report.blas_threads, 1);  // 0 when no OpenBLAS is loaded
  EXPECT_LE(report.openmp_threads, 1);
  report = set_thread_policy({.threads = 2, .blas_threads = 0});
  EXPECT_EQ(max_threads(), 2);
  if (report.blas_threads > 0) {
    EXPECT_EQ(report.blas_threads, 2);
  }
  report = set_thread_policy({});
  EXPECT_EQ(report.threads, available_cores());
  EXPECT_LE(report.blas_threads, 1);
}

TEST(ThreadPolicy, RejectsNegativeCounts) {
  EXPECT_THROW(set_thread_policy({.threads = -1}), InputError);
  EXPECT_THROW(set_thread_policy({.threads = 1, .blas_threads = -2}), InputError);
  set_thread_policy({});
}

}  // namespace
}  // namespace strata
