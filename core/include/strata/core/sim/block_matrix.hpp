#pragma once
/// \file block_matrix.hpp
/// A symmetric matrix of 3 × 3 blocks (a Newton system whose vertices have all three DOFs free),
/// stored by block columns with each block's nine values together. Copied from a compressed
/// matrix whose pattern is made of whole blocks, it multiplies a vector with one row index and
/// one three-entry read of x per block, and reads its values as one stream: the products of CG
/// and of the multigrid smoothers.
#include <functional>
#include <vector>

#include "strata/core/common/fill_vector.hpp"
#include "strata/core/common/types.hpp"

namespace strata {

class BlockSymmetricMatrix {
 public:
  /// Copies A (square, compressed, column-major, symmetric with both triangles) when its pattern
  /// is made of whole 3 × 3 blocks: 3n columns, the columns 3b, 3b + 1, 3b + 2 holding the same
  /// rows, which come in triples 3a, 3a + 1, 3a + 2. Returns false (and holds nothing) otherwise.
  bool assign(const SparseMatrixd& A);
  void clear();
  /// Whether assign() also keeps the values rounded to single precision (written in the same
  /// pass), for multiply_single(). Takes effect at the next assign().
  void keep_single_precision(bool keep) { m_keep_single = keep; }
  /// Whether the last assign() kept the rounded values.
  bool has_single_precision() const {
    return m_num_blocks > 0 && m_single.size() == m_values.size();
  }
  bool empty() const { return m_num_blocks == 0; }
  Index rows() const { return 3 * m_num_blocks; }
  /// The blocks as assigned: those of block column b are block_outer()[b] … [b + 1], block e in
  /// block row block_rows()[e], its entry (i, j) at block_values()[9e + 3j + i].
  const int* block_outer() const { return m_outer.data(); }
  const int* block_rows() const { return m_block_rows.data(); }
  const double* block_values() const { return m_values.data(); }

  /// Block columns per parallel chunk of the products.
  static constexpr Index kBlockChunk = 512;

  /// y = A x (A as assigned), in parallel over block columns; the result does not depend on the
  /// thread count.
  void multiply(ConstRef<VectorXd> x, VectorXd& y) const;
  /// y = A x, and after each chunk of kBlockChunk block columns, on the thread that computed it,
  /// `after(begin, end)` on the rows [begin, end) of y just written (which it may change, but no
  /// entry of x, which other chunks read). Returns the sum of its values, added chunk by chunk
  /// in order: the same at any thread count (0 for an empty `after`).
  double multiply(ConstRef<VectorXd> x, VectorXd& y,
                  const std::function<double(Index, Index)>& after) const;
  /// The same product by the values rounded to single precision (has_single_precision()), which
  /// reads 40 bytes per block instead of 76; x, y and the sums stay in double.
  double multiply_single(ConstRef<VectorXd> x, VectorXd& y,
                         const std::function<double(Index, Index)>& after) const;

 private:
  Index m_num_blocks = 0;
  std::vector<int> m_outer;      ///< block column b: blocks m_outer[b] .. m_outer[b + 1]
  FillVector<int> m_block_rows;  ///< block row a of each block
  FillVector<double> m_values;   ///< 9 per block: entry (i, j) at 3j + i
  FillVector<float> m_single;    ///< m_values rounded, when m_keep_single
  bool m_keep_single = false;

  template <typename Scalar>
  double product(const Scalar* values, ConstRef<VectorXd> x, VectorXd& y,
                 const std::function<double(Index, Index)>& after) const;
};

}  // namespace strata
