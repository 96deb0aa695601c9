#include "strata/hierarchy/edge_midpoint_map.hpp"

#include <algorithm>

#include "strata/core/common/error.hpp"

namespace strata {

std::uint64_t EdgeMidpointMap::make_key(int a, int b) {
  STRATA_VERIFY(a >= 0 && b >= 0 && a != b, "edge needs two distinct vertices");
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

std::size_t EdgeMidpointMap::home(std::uint64_t key) const {
  // splitmix64 finaliser: neighbouring vertex ids spread over the whole table.
  key ^= key >> 30;
  key *= 0xbf58476d1ce4e5b9ULL;
  key ^= key >> 27;
  key *= 0x94d049bb133111ebULL;
  key ^= key >> 31;
  return static_cast<std::size_t>(key) & (m_slots.size() - 1);
}

std::size_t EdgeMidpointMap::probe(std::uint64_t key) const {
  const std::size_t mask = m_slots.size() - 1;
  std::size_t slot = home(key);
  while (m_slots[slot].key != key && m_slots[slot].key != kEmpty)
    slot = (slot + 1) & mask;
  return slot;
}

int EdgeMidpointMap::find(int a, int b) const {
  if (m_size == 0) return -1;
  const std::uint64_t key = make_key(a, b);
  return m_slots[probe(key)].vertex;
}

void EdgeMidpointMap::insert(int a, int b, int vertex) {
  const std::uint64_t key = make_key(a, b);
  if (2 * (m_size + 1) > m_slots.size()) grow();
  const std::size_t slot = probe(key);
  STRATA_VERIFY(m_slots[slot].key == kEmpty, "edge already has a midpoint");
  m_slots[slot] = {key, vertex};
  ++m_size;
}

bool EdgeMidpointMap::erase(int a, int b) {
  if (m_size == 0) return false;
  const std::size_t mask = m_slots.size() - 1;
  std::size_t hole = probe(make_key(a, b));
  if (m_slots[hole].key == kEmpty) return false;
  // Backward shift: move later members of the probe run into the hole unless that would put them
  // before their home slot.
  for (std::size_t next = (hole + 1) & mask; m_slots[next].key != kEmpty;
       next = (next + 1) & mask) {
    const std::size_t next_home = home(m_slots[next].key);
    const bool movable = ((next - next_home) & mask) >= ((next - hole) & mask);
    if (movable) {
      m_slots[hole] = m_slots[next];
      hole = next;
    }
  }
  m_slots[hole] = Slot{};
  --m_size;
  return true;
}

void EdgeMidpointMap::grow() {
  std::vector<Slot> old = std::move(m_slots);
  m_slots.assign(std::max<std::size_t>(16, 2 * old.size()), Slot{});
  for (const Slot& slot : old)
    if (slot.key != kEmpty) m_slots[probe(slot.key)] = slot;
}

}  // namespace strata
