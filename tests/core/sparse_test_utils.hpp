#pragma once
/// Random sparse matrices for the tests of the solve layer.
#include <random>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata::testing {

/// A random symmetric matrix of 3 × 3 blocks over `num_blocks` block rows: a dense diagonal block
/// per block column and `per_column` random off-diagonal blocks (mirrored), every entry of a
/// present block stored (some of them exact zeros, as assembled matrices hold).
inline SparseMatrixd random_block_matrix(Index num_blocks, int per_column, std::mt19937& random) {
  std::uniform_int_distribution<Index> index(0, num_blocks - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> triplets;
  auto add_block = [&](Index a, Index b) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        if (a == b && j < i) continue;  // a diagonal block: its upper triangle, mirrored
        const double v = (i + j) % 4 == 3 ? 0.0 : value(random);
        triplets.emplace_back(3 * a + i, 3 * b + j, v);
        if (a != b || i != j) triplets.emplace_back(3 * b + j, 3 * a + i, v);
      }
  };
  for (Index b = 0; b < num_blocks; ++b) {
    add_block(b, b);
    for (int k = 0; k < per_column; ++k) {
      const Index a = index(random);
      if (a != b) add_block(a, b);
    }
  }
  SparseMatrixd A(3 * num_blocks, 3 * num_blocks);
  A.setFromTriplets(triplets.begin(), triplets.end());  // duplicates summed: still whole blocks
  return A;
}

}  // namespace strata::testing
