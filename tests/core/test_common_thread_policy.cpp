// The process-wide thread policy: TBB follows the requested count; the BLAS and OpenMP libraries
// behind CHOLMOD (when loaded) are set to their own counts.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>

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

// CHOLMOD's supernodal factorisation opens OpenMP regions with a fixed team size (4 threads were
// seen on 2 cores), which omp_set_num_threads alone does not cap. Such a region, opened through
// libgomp's entry point as compiled code opens it, must run on at most the policy's OpenMP threads.
std::atomic<int> g_team_size{0};
void record_team_size(void*) {
  using Query = int (*)();
  static const auto team_size = reinterpret_cast<Query>(dlsym(RTLD_DEFAULT, "omp_get_num_threads"));
  g_team_size.store(std::max(g_team_size.load(), team_size()));
}

TEST(ThreadPolicy, CapsFixedSizeOpenMpRegions) {
  using Parallel = void (*)(void (*)(void*), void*, unsigned, unsigned);
  const auto parallel = reinterpret_cast<Parallel>(dlsym(RTLD_DEFAULT, "GOMP_parallel"));
  if (parallel == nullptr || dlsym(RTLD_DEFAULT, "omp_get_num_threads") == nullptr)
    GTEST_SKIP() << "libgomp is not loaded";
  for (const int openmp : {1, 2}) {
    const ThreadReport report = set_thread_policy({.threads = 2, .openmp_threads = openmp});
    EXPECT_EQ(report.openmp_threads, openmp);
    g_team_size = 0;
    parallel(record_team_size, nullptr, 4, 0);
    EXPECT_GE(g_team_size.load(), 1);
    EXPECT_LE(g_team_size.load(), openmp);
  }
  set_thread_policy({});
}

TEST(ThreadPolicy, RejectsNegativeCounts) {
  EXPECT_THROW(set_thread_policy({.threads = -1}), InputError);
  EXPECT_THROW(set_thread_policy({.threads = 1, .blas_threads = -2}), InputError);
  EXPECT_THROW(set_thread_policy({.threads = 1, .openmp_threads = -1}), InputError);
  set_thread_policy({});
}

}  // namespace
}  // namespace strata
