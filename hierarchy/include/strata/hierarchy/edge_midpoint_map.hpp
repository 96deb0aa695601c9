#pragma once
/// \file edge_midpoint_map.hpp
/// Hash map from an (unordered) vertex pair to the vertex at the pair's midpoint: the shared-vertex
/// table of red refinement (MFEM's ncmesh keeps the same "mid-edge node" hash). Two neighbours that
/// refine a common edge find the same midpoint here, so the refined mesh is conforming.
///
/// Open addressing with linear probing and backward-shift deletion over 16-byte slots; the table
/// doubles when half full and never shrinks (its size follows the largest number of midpoints
/// that existed at once).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace strata {

class EdgeMidpointMap {
 public:
  EdgeMidpointMap() = default;

  /// The midpoint vertex of edge {a, b} (order irrelevant), or −1 if none is recorded.
  int find(int a, int b) const;

  /// Records `vertex` as the midpoint of {a, b}. Precondition: {a, b} has none (checked).
  void insert(int a, int b, int vertex);

  /// Forgets the midpoint of {a, b}; returns whether there was one.
  bool erase(int a, int b);

  /// Number of recorded midpoints.
  std::size_t size() const { return m_size; }
  /// Number of slots (a power of two, or 0 before the first insertion).
  std::size_t capacity() const { return m_slots.size(); }
  /// Bytes held by the slot array.
  std::size_t memory_bytes() const { return m_slots.capacity() * sizeof(Slot); }

 private:
  struct Slot {
    std::uint64_t key = kEmpty;
    int vertex = -1;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  static std::uint64_t make_key(int a, int b);
  std::size_t home(std::uint64_t key) const;
  /// Slot holding `key`, or the empty slot where the probe for it ends.
  std::size_t probe(std::uint64_t key) const;
  void grow();

  std::vector<Slot> m_slots;
  std::size_t m_size = 0;
};

}  // namespace strata
