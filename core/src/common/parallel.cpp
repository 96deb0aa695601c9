#include "strata/core/common/parallel.hpp"

#include <dlfcn.h>
#include <sched.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <string>
#include <thread>

#include "strata/core/common/error.hpp"

namespace strata {

struct ThreadLimit::Impl {
  explicit Impl(int num_threads)
      : control(tbb::global_control::max_allowed_parallelism, std::max(1, num_threads)) {}
  tbb::global_control control;
};

ThreadLimit::ThreadLimit(int num_threads) : m_impl(std::make_unique<Impl>(num_threads)) {}

ThreadLimit::~ThreadLimit() = default;

int max_threads() {
  return static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

int available_cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

/// Calls `void name(int)` if some loaded library defines it; returns whether it did.
bool call_if_loaded(const char* name, int value) {
  using Setter = void (*)(int);
  void* symbol = dlsym(RTLD_DEFAULT, name);
  if (symbol == nullptr) return false;
  reinterpret_cast<Setter>(symbol)(value);
  return true;
}

int query_if_loaded(const char* name) {
  using Getter = int (*)();
  void* symbol = dlsym(RTLD_DEFAULT, name);
  return symbol == nullptr ? 0 : reinterpret_cast<Getter>(symbol)();
}

}  // namespace

ThreadReport set_thread_policy(const ThreadPolicy& policy) {
  if (policy.threads < 0) throw InputError("threads: must be >= 0 (0 = every core)");
  if (policy.blas_threads < 0) throw InputError("blas threads: must be >= 0");
  if (policy.openmp_threads < 0) throw InputError("openmp threads: must be >= 0");
  static std::unique_ptr<ThreadLimit> process_limit;
  const int threads = policy.threads > 0 ? policy.threads : available_cores();
  const int blas = policy.blas_threads > 0 ? policy.blas_threads : threads;
  const int openmp = policy.openmp_threads > 0 ? policy.openmp_threads : threads;
  process_limit.reset();
  process_limit = std::make_unique<ThreadLimit>(threads);
  ThreadReport report;
  report.threads = max_threads();
  // OpenMP first: an OpenBLAS built on OpenMP sets the OpenMP count itself, and must keep its own.
  const bool has_openmp = call_if_loaded("omp_set_num_threads", openmp);
  // With dynamic adjustment libgomp caps a num_threads(k) clause by the count above.
  if (has_openmp) call_if_loaded("omp_set_dynamic", 1);
  if (call_if_loaded("openblas_set_num_threads", blas))
    report.blas_threads = query_if_loaded("openblas_get_num_threads");
  if (has_openmp) report.openmp_threads = query_if_loaded("omp_get_max_threads");
  return report;
}

}  // namespace strata
