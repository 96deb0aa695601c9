#pragma once
/// \file monotone_arena.hpp
/// Memory handed out at increasing addresses, for CGAL containers whose algorithms order their
/// elements by address. CGAL's Polyhedron_3 compares handles as pointers (In_place_list), and its
/// mean-curvature-flow skeletonization collapses edges in the order of a std::set of such handles:
/// with the general-purpose heap, that order — and the skeleton — depends on whatever the process
/// allocated and freed before. From one arena, addresses follow the order of allocation, so the
/// same surface always gives the same skeleton.
///
/// Include this before any CGAL header and define CGAL_ALLOCATOR(T) as
/// strata::detail::MonotoneAllocator<T>; while a MonotoneArena is alive on a thread, the CGAL
/// containers that thread creates draw from it (freed memory is not reused until the arena ends).
/// Outside an arena the allocator is std::allocator. Arenas do not nest, and one that cannot
/// reserve its address space is inactive (std::allocator, no address order).
#include <sys/mman.h>

#include <cstddef>
#include <memory>
#include <new>

namespace strata::detail {

class MonotoneArena {
 public:
  /// Reserves `capacity` bytes of address space (pages are committed as they are touched). If the
  /// system refuses the reservation, the arena is inactive (reserved() is false) and the
  /// allocator uses std::allocator.
  explicit MonotoneArena(std::size_t capacity) {
    void* base = mmap(nullptr, capacity, PROT_READ | PROT_WRITE,
                      MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (base == MAP_FAILED) return;
    m_base = static_cast<char*>(base);
    m_capacity = capacity;
    m_previous = s_active;
    s_active = this;
  }
  ~MonotoneArena() {
    if (m_base == nullptr) return;
    s_active = m_previous;
    munmap(m_base, m_capacity);
  }
  bool reserved() const { return m_base != nullptr; }
  MonotoneArena(const MonotoneArena&) = delete;
  MonotoneArena& operator=(const MonotoneArena&) = delete;

  void* allocate(std::size_t bytes, std::size_t alignment) {
    const std::size_t start = (m_used + alignment - 1) / alignment * alignment;
    if (start > m_capacity || bytes > m_capacity - start) throw std::bad_alloc();
    m_used = start + bytes;
    return m_base + start;
  }
  bool owns(const void* p) const {
    const char* c = static_cast<const char*>(p);
    return c >= m_base && c < m_base + m_capacity;
  }
  std::size_t used() const { return m_used; }
  std::size_t capacity() const { return m_capacity; }

  /// The arena of this thread, if one is alive.
  static MonotoneArena* active() { return s_active; }

 private:
  char* m_base = nullptr;
  std::size_t m_capacity = 0;
  std::size_t m_used = 0;
  MonotoneArena* m_previous = nullptr;
  static inline thread_local MonotoneArena* s_active = nullptr;
};

template <class T>
struct MonotoneAllocator {
  using value_type = T;
  template <class U>
  struct rebind {
    using other = MonotoneAllocator<U>;
  };
  MonotoneAllocator() = default;
  template <class U>
  MonotoneAllocator(const MonotoneAllocator<U>&) {}

  T* allocate(std::size_t n) {
    if (MonotoneArena* arena = MonotoneArena::active()) {
      if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_alloc();
      return static_cast<T*>(arena->allocate(n * sizeof(T), alignof(T)));
    }
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) {
    // Memory of a live arena is released with it; anything else came from std::allocator (an
    // arena never outlives the containers that used it).
    if (MonotoneArena* arena = MonotoneArena::active(); arena != nullptr && arena->owns(p)) return;
    std::allocator<T>().deallocate(p, n);
  }
  // The pre-C++17 members CGAL's containers still use.
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  void destroy(U* p) {
    p->~U();
  }
};

template <class T, class U>
bool operator==(const MonotoneAllocator<T>&, const MonotoneAllocator<U>&) {
  return true;
}
template <class T, class U>
bool operator!=(const MonotoneAllocator<T>&, const MonotoneAllocator<U>&) {
  return false;
}

}  // namespace strata::detail
