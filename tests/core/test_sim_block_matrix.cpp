// BlockSymmetricMatrix (block_matrix.hpp): products against dense ones on stiffness-like block
// patterns, and the patterns it must refuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "sparse_test_utils.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/sim/block_matrix.hpp"
#include "strata/core/sim/multigrid.hpp"

namespace strata {
namespace {

using testing::random_block_matrix;

TEST(BlockSymmetricMatrix, ProductMatchesDense) {
  std::mt19937 random(7);
  for (const Index num_blocks : {1, 5, 400, 700}) {
    const SparseMatrixd A = random_block_matrix(num_blocks, 6, random);
    BlockSymmetricMatrix blocks;
    ASSERT_TRUE(blocks.assign(A)) << num_blocks;
    EXPECT_EQ(blocks.rows(), A.rows());
    ASSERT_EQ((Eigen::MatrixXd(A) - Eigen::MatrixXd(A).transpose()).norm(), 0.0);
    const VectorXd x = VectorXd::Random(A.rows());
    VectorXd y;
    blocks.multiply(x, y);
    const VectorXd expected = Eigen::MatrixXd(A) * x;
    EXPECT_LE((y - expected).norm(), 1e-13 * expected.norm()) << num_blocks;
    VectorXd scalar;
    symmetric_product(A, x, scalar);
    EXPECT_LE((y - scalar).norm(), 1e-13 * expected.norm()) << num_blocks;
  }
}

TEST(BlockSymmetricMatrix, ValuesFollowAReassignment) {
  std::mt19937 random(11);
  SparseMatrixd A = random_block_matrix(50, 4, random);
  BlockSymmetricMatrix blocks;
  ASSERT_TRUE(blocks.assign(A));
  A *= 2.5;
  ASSERT_TRUE(blocks.assign(A));
  const VectorXd x = VectorXd::Random(A.rows());
  VectorXd y;
  blocks.multiply(x, y);
  const VectorXd expected = Eigen::MatrixXd(A) * x;
  EXPECT_LE((y - expected).norm(), 1e-13 * expected.norm());
}

TEST(BlockSymmetricMatrix, RefusesPatternsWithoutWholeBlocks) {
  std::mt19937 random(3);
  const SparseMatrixd A = random_block_matrix(20, 3, random);
  BlockSymmetricMatrix blocks;

  // A DOF of one vertex eliminated (a Dirichlet condition on one coordinate).
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index j = 0; j < A.outerSize(); ++j)
    for (SparseMatrixd::InnerIterator it(A, j); it; ++it)
      if (it.row() != 4 && j != 4)
        triplets.emplace_back(it.row() - (it.row() > 4), j - (j > 4), it.value());
  SparseMatrixd reduced(A.rows() - 1, A.cols() - 1);
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  EXPECT_FALSE(blocks.assign(reduced));
  EXPECT_TRUE(blocks.empty());

  // One entry of a diagonal block pruned: the three columns of block column 0 differ.
  SparseMatrixd pruned = A;
  pruned.prune([](Index i, Index j, double) { return !(i == 2 && j == 1); });
  pruned.makeCompressed();
  ASSERT_EQ(pruned.nonZeros(), A.nonZeros() - 1);
  EXPECT_FALSE(blocks.assign(pruned));

  // Columns of equal length whose rows are not whole blocks: block column 0 holds rows 0–2 and
  // 4–6 (a block shifted by one row).
  std::vector<Eigen::Triplet<double>> shifted;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      shifted.emplace_back(i, j, 1.0);
      shifted.emplace_back(4 + i, j, 1.0);
    }
  }
  SparseMatrixd misaligned(9, 9);
  misaligned.setFromTriplets(shifted.begin(), shifted.end());
  EXPECT_FALSE(blocks.assign(misaligned));

  // Columns of one length whose rows differ: column 1 of block column 0 holds block row 2 where
  // columns 0 and 2 hold block row 1.
  std::vector<Eigen::Triplet<double>> differing;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      differing.emplace_back(i, j, 1.0);
      differing.emplace_back((j == 1 ? 6 : 3) + i, j, 1.0);
    }
  SparseMatrixd crossed(9, 9);
  crossed.setFromTriplets(differing.begin(), differing.end());
  EXPECT_FALSE(blocks.assign(crossed));

  // A large matrix whose only fault is in its last block column (the check runs in ranges).
  const SparseMatrixd large = random_block_matrix(3000, 4, random);
  ASSERT_TRUE(blocks.assign(large));
  SparseMatrixd faulty = large;
  faulty.prune([&](Index i, Index j, double) { return !(i == j && j == large.cols() - 2); });
  faulty.makeCompressed();
  ASSERT_EQ(faulty.nonZeros(), large.nonZeros() - 1);
  EXPECT_FALSE(blocks.assign(faulty));

  // A matrix that is not square in blocks, and one left uncompressed.
  EXPECT_FALSE(blocks.assign(SparseMatrixd(4, 4)));
  SparseMatrixd uncompressed = A;
  uncompressed.coeffRef(0, 0) += 1.0;
  uncompressed.reserve(Eigen::VectorXi::Constant(A.cols(), 2));
  EXPECT_FALSE(blocks.assign(uncompressed));

  // Still usable afterwards.
  EXPECT_TRUE(blocks.assign(A));
  EXPECT_EQ(blocks.rows(), A.rows());
}

TEST(BlockSymmetricMatrix, ProductDoesNotDependOnTheThreadCount) {
  std::mt19937 random(5);
  const SparseMatrixd A = random_block_matrix(6000, 8, random);
  BlockSymmetricMatrix blocks;
  ASSERT_TRUE(blocks.assign(A));
  const VectorXd x = VectorXd::Random(A.rows());
  VectorXd one, two, scalar;
  set_thread_policy({.threads = 1});
  blocks.multiply(x, one);
  set_thread_policy({.threads = 2});
  blocks.multiply(x, two);
  set_thread_policy({});
  EXPECT_EQ(one, two);
  symmetric_product(A, x, scalar);
  EXPECT_LE((one - scalar).norm(), 1e-13 * scalar.norm());
}

TEST(BlockSymmetricMatrix, AfterEachChunkSeesItsRowsAndSumsInChunkOrder) {
  // y = A x with, after each chunk, y's rows set to y − x there and their squared norm returned:
  // the rows the callback sees are the chunk's own, already computed, and the sum is the chunks'
  // partial sums in order, at one and two threads alike.
  std::mt19937 random(11);
  const Index num_blocks = 5 * BlockSymmetricMatrix::kBlockChunk + 77;
  const SparseMatrixd A = random_block_matrix(num_blocks, 6, random);
  BlockSymmetricMatrix blocks;
  ASSERT_TRUE(blocks.assign(A));
  const VectorXd x = VectorXd::Random(A.rows());
  VectorXd plain;
  blocks.multiply(x, plain);
  const VectorXd expected_y = plain - x;
  double expected_sum = 0.0;
  for (Index first = 0; first < num_blocks; first += BlockSymmetricMatrix::kBlockChunk) {
    const Index rows = 3 * std::min(BlockSymmetricMatrix::kBlockChunk, num_blocks - first);
    expected_sum += expected_y.segment(3 * first, rows).squaredNorm();
  }
  for (const int threads : {1, 2}) {
    set_thread_policy({.threads = threads});
    VectorXd y;
    int misplaced = 0;
    const double sum = blocks.multiply(x, y, [&](Index begin, Index end) {
      if (begin % (3 * BlockSymmetricMatrix::kBlockChunk) != 0 || end > y.size()) ++misplaced;
      y.segment(begin, end - begin) -= x.segment(begin, end - begin);
      return y.segment(begin, end - begin).squaredNorm();
    });
    EXPECT_EQ(misplaced, 0) << threads;
    EXPECT_EQ(y, expected_y) << threads;
    EXPECT_EQ(sum, expected_sum) << threads;
  }
  set_thread_policy({});
  // No callback: the plain product, and 0.
  VectorXd y;
  EXPECT_EQ(blocks.multiply(x, y, {}), 0.0);
  EXPECT_EQ(y, plain);
}

}  // namespace
}  // namespace strata
