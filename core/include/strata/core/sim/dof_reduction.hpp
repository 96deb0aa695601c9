#pragma once
/// \file dof_reduction.hpp
/// Elimination of Dirichlet DOFs from Newton systems: maps 3·#V vectors and matrices in a fixed
/// sparsity pattern to the free DOFs only. The reduced pattern and the value map are built once,
/// so reducing a matrix is a gather of its values.
#include <vector>

#include "strata/core/common/fill_vector.hpp"
#include "strata/core/common/types.hpp"

namespace strata {

class DofReduction {
 public:
  /// `pattern`: the full (3·#V square, compressed) pattern every reduced matrix will have;
  /// `constrained`: 3·#V flags, non-zero for eliminated DOFs.
  DofReduction(const SparseMatrixd& pattern, const std::vector<char>& constrained);

  Index num_free() const { return static_cast<Index>(m_free.size()); }
  /// Free DOF indices, ascending.
  const std::vector<Index>& free_dofs() const { return m_free; }

  /// full[free] (num_free entries).
  VectorXd restrict_vector(ConstRef<VectorXd> full) const;
  /// full[free] += reduced.
  void add_prolonged(ConstRef<VectorXd> reduced, VectorXd& full) const;
  /// The free–free block of `full`, which must have exactly the pattern given at construction.
  /// `reduced` gets the reduced pattern unless it has the reduced size, non-zeros and column
  /// starts already (its rows are then taken to be the reduced pattern's: pass a matrix this
  /// reduction filled, or any other); only the values are written then.
  void restrict_matrix(const SparseMatrixd& full, SparseMatrixd& reduced) const;

 private:
  std::vector<Index> m_free;
  /// The reduced pattern's column starts and rows (its values are those of each matrix reduced).
  std::vector<int> m_outer;
  FillVector<int> m_inner;
  FillVector<int> m_source;  ///< for each reduced value, its index in the full value array
  Index m_full_nonzeros = 0;
};

}  // namespace strata
