#pragma once
/// \file parallel.hpp
/// Thread control. strata's own loops run on TBB; the BLAS behind CHOLMOD (OpenBLAS) and OpenMP
/// start threads of their own. On few cores these oversubscribe them: BLAS and OpenMP threads
/// spin-wait while TBB's workers run and the reverse, which shows as system time. One process-wide
/// policy (`set_thread_policy`) sets all three: TBB to N threads, OpenBLAS to
/// `ThreadPolicy::blas_threads` (default 1) and OpenMP to `ThreadPolicy::openmp_threads` (default
/// N) with dynamic adjustment. OpenMP's settings belong to the thread that applies the policy (in
/// libgomp they are per thread): sparse solves run on that thread, as they do in the CLI.
#include <memory>

namespace strata {

/// While alive, limits strata's parallel loops to `num_threads` threads (1 = serial).
class ThreadLimit {
 public:
  explicit ThreadLimit(int num_threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Number of threads TBB will currently use.
int max_threads();

/// Number of cores this process may run on (its CPU affinity mask; at least 1).
int available_cores();

struct ThreadPolicy {
  int threads = 0;       ///< TBB threads; 0 = available_cores()
  int blas_threads = 1;  ///< OpenBLAS threads (0 = same as `threads`)
  /// OpenMP threads (0 = same as `threads`): CHOLMOD's supernodal factorisation runs OpenMP
  /// regions while strata's TBB loops wait. They ran with a team of 4 threads on 2 cores, a fixed
  /// request that omp_set_num_threads alone does not cap; the policy turns on OpenMP's dynamic
  /// adjustment, under which a region gets at most this many (fewer when the machine is loaded).
  int openmp_threads = 0;
};

/// What the policy set. A library that is not loaded (or not OpenBLAS / not OpenMP) reports 0.
struct ThreadReport {
  int threads = 0;
  int blas_threads = 0;
  int openmp_threads = 0;
};

/// Applies `policy` for the rest of the process (replacing an earlier one). Throws InputError for
/// negative counts.
ThreadReport set_thread_policy(const ThreadPolicy& policy);

}  // namespace strata
