#pragma once
/// \file parallel.hpp
/// Thread control for strata's TBB loops. By default TBB uses every core; tests and benchmarks can
/// force a count.
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

}  // namespace strata
