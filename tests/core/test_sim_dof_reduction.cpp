// The Dirichlet reduction of Newton systems: the free–free block of a matrix in the construction
// pattern, compared with the block taken entry by entry from the dense matrix, and the target
// matrix's pattern set (or reset) before its values are gathered.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "sparse_test_utils.hpp"
#include "strata/core/sim/dof_reduction.hpp"

namespace strata {
namespace {

using testing::random_block_matrix;

/// The free–free block of A, entry by entry.
Eigen::MatrixXd dense_free_block(const SparseMatrixd& A, const std::vector<char>& constrained) {
  std::vector<Index> free;
  for (Index i = 0; i < A.rows(); ++i)
    if (!constrained[i]) free.push_back(i);
  const Eigen::MatrixXd dense(A);
  Eigen::MatrixXd block(free.size(), free.size());
  for (std::size_t r = 0; r < free.size(); ++r)
    for (std::size_t c = 0; c < free.size(); ++c)
      block(r, c) = dense(free[r], free[c]);
  return block;
}

TEST(DofReduction, TheFreeBlockOfEachMatrixInThePattern) {
  std::mt19937 random(7);
  const Index n = 60;
  const SparseMatrixd A = random_block_matrix(n, 4, random);
  // Whole vertices and single coordinates constrained.
  std::vector<char> constrained(3 * n, 0);
  std::bernoulli_distribution pick(0.2);
  for (Index i = 0; i < 3 * n; ++i)
    constrained[i] = pick(random) ? 1 : 0;
  for (int i = 0; i < 3; ++i)
    constrained[3 * 5 + i] = 1;
  const DofReduction reduction(A, constrained);
  SparseMatrixd reduced;
  reduction.restrict_matrix(A, reduced);
  ASSERT_EQ(reduced.rows(), reduction.num_free());
  EXPECT_TRUE(reduced.isCompressed());
  EXPECT_EQ(Eigen::MatrixXd(reduced), dense_free_block(A, constrained));

  // The next matrix of the pattern, into the same target.
  SparseMatrixd B = A;
  for (Index k = 0; k < B.nonZeros(); ++k)
    B.valuePtr()[k] = 2.0 * B.valuePtr()[k] + 1.0;
  reduction.restrict_matrix(B, reduced);
  EXPECT_EQ(Eigen::MatrixXd(reduced), dense_free_block(B, constrained));

  // A target holding another pattern with as many non-zeros (its first columns full) gets the
  // reduction's pattern.
  SparseMatrixd other(reduced.rows(), reduced.cols());
  std::vector<Eigen::Triplet<double>> leading_columns;
  for (Index k = 0; k < reduced.nonZeros(); ++k)
    leading_columns.emplace_back(k % reduced.rows(), k / reduced.rows(), 1.0);
  other.setFromTriplets(leading_columns.begin(), leading_columns.end());
  other.makeCompressed();
  ASSERT_EQ(other.nonZeros(), reduced.nonZeros());
  reduction.restrict_matrix(B, other);
  EXPECT_EQ(Eigen::MatrixXd(other), dense_free_block(B, constrained));
  // A matrix of another pattern is refused.
  const SparseMatrixd C = random_block_matrix(n, 5, random);
  ASSERT_NE(C.nonZeros(), A.nonZeros());
  EXPECT_THROW(reduction.restrict_matrix(C, reduced), std::logic_error);
}

}  // namespace
}  // namespace strata
