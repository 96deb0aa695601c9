#include "strata/core/sim/dof_reduction.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "strata/core/common/error.hpp"

namespace strata {

DofReduction::DofReduction(const SparseMatrixd& pattern, const std::vector<char>& constrained) {
  STRATA_VERIFY(pattern.isCompressed() && pattern.rows() == pattern.cols() &&
                    static_cast<size_t>(pattern.rows()) == constrained.size(),
                "DofReduction: pattern must be compressed, square and match the DOF mask");
  std::vector<int> reduced_index(constrained.size(), -1);
  for (size_t i = 0; i < constrained.size(); ++i) {
    if (constrained[i]) continue;
    reduced_index[i] = static_cast<int>(m_free.size());
    m_free.push_back(static_cast<Index>(i));
  }
  // Removing rows and columns keeps each column's rows ascending: the reduced pattern is the
  // full one filtered, with the source of every value kept.
  m_reduced_pattern.resize(num_free(), num_free());
  const int* full_outer = pattern.outerIndexPtr();
  const int* full_inner = pattern.innerIndexPtr();
  int* outer = m_reduced_pattern.outerIndexPtr();
  outer[0] = 0;
  tbb::parallel_for(Index(0), num_free(), [&](Index c) {
    int count = 0;
    for (Index p = full_outer[m_free[c]]; p < full_outer[m_free[c] + 1]; ++p)
      count += reduced_index[full_inner[p]] >= 0;
    outer[c + 1] = count;
  });
  for (Index c = 0; c < num_free(); ++c)
    outer[c + 1] += outer[c];
  const Index nnz = outer[num_free()];
  m_reduced_pattern.resizeNonZeros(nnz);
  m_source.resize(nnz);
  int* inner = m_reduced_pattern.innerIndexPtr();
  double* values = m_reduced_pattern.valuePtr();
  tbb::parallel_for(Index(0), num_free(), [&](Index c) {
    Index k = outer[c];
    for (int p = full_outer[m_free[c]]; p < full_outer[m_free[c] + 1]; ++p) {
      const int row = reduced_index[full_inner[p]];
      if (row < 0) continue;
      inner[k] = row;
      values[k] = 0.0;
      m_source[k++] = p;
    }
  });
  m_full_nonzeros = pattern.nonZeros();
}

VectorXd DofReduction::restrict_vector(ConstRef<VectorXd> full) const {
  VectorXd reduced(num_free());
  for (Index k = 0; k < num_free(); ++k)
    reduced[k] = full[m_free[k]];
  return reduced;
}

void DofReduction::add_prolonged(ConstRef<VectorXd> reduced, VectorXd& full) const {
  for (Index k = 0; k < num_free(); ++k)
    full[m_free[k]] += reduced[k];
}

void DofReduction::restrict_matrix(const SparseMatrixd& full, SparseMatrixd& reduced) const {
  STRATA_VERIFY(full.nonZeros() == m_full_nonzeros && full.isCompressed(),
                "DofReduction: matrix does not have the construction pattern");
  if (reduced.rows() != num_free() || reduced.nonZeros() != m_reduced_pattern.nonZeros())
    reduced = m_reduced_pattern;
  double* values = reduced.valuePtr();
  const double* source = full.valuePtr();
  const int* from = m_source.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m_source.size(), 16384),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k)
                        values[k] = source[from[k]];
                    });
}

}  // namespace strata
