#pragma once
/// \file fill_vector.hpp
/// FillVector<T>: a std::vector whose resize leaves new elements of trivial types uninitialised,
/// for large arrays that are written in full right after, in parallel. A std::vector would
/// zero-fill them first on one thread; here each memory page is first touched (and zeroed by the
/// kernel) by the thread that fills it.
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace strata {

/// std::allocator whose value-initialisation (construct without arguments) default-initialises.
template <typename T>
class DefaultInitAllocator : public std::allocator<T> {
 public:
  using value_type = T;
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() noexcept = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using FillVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace strata
