#include "strata/core/common/parallel.hpp"

#include <tbb/global_control.h>

#include <algorithm>

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

}  // namespace strata
