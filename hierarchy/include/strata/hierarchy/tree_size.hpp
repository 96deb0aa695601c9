#pragma once
/// \file tree_size.hpp
/// Sizes of the nested-tet tree (the Hierarchy issue builds the tree itself).
#include <cstdint>

namespace strata {

/// Number of potential leaves when every one of `coarse_tets` roots is red-refined (1:8) `levels`
/// times: coarse_tets · 8^levels.
std::uint64_t potential_leaf_count(std::uint64_t coarse_tets, int levels);

}  // namespace strata
