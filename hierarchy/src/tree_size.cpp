#include "strata/hierarchy/tree_size.hpp"

#include <stdexcept>

namespace strata {

std::uint64_t potential_leaf_count(std::uint64_t coarse_tets, int levels) {
  if (levels < 0) throw std::invalid_argument("potential_leaf_count: levels must be >= 0");
  std::uint64_t count = coarse_tets;
  for (int level = 0; level < levels; ++level)
    count *= 8;
  return count;
}

}  // namespace strata
