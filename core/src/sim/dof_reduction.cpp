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
  m_outer.assign(num_free() + 1, 0);
  const int* full_outer = pattern.outerIndexPtr();
  const int* full_inner = pattern.innerIndexPtr();
  int* outer = m_outer.data();
  tbb::parallel_for(Index(0), num_free(), [&](Index c) {
    int count = 0;
    for (Index p = full_outer[m_free[c]]; p < full_outer[m_free[c] + 1]; ++p)
      count += reduced_index[full_inner[p]] >= 0;
    outer[c + 1] = count;
  });
  for (Index c = 0; c < num_free(); ++c)
    outer[c + 1] += outer[c];
  const Index nnz = outer[num_free()];
  m_inner.resize(nnz);
  m_source.resize(nnz);
  int* inner = m_inner.data();
  tbb::parallel_for(Index(0), num_free(), [&](Index c) {
    Index k = outer[c];
    for (int p = full_outer[m_free[c]]; p < full_outer[m_free[c] + 1]; ++p) {
      const int row = reduced_index[full_inner[p]];
      if (row < 0) continue;
      inner[k] = row;
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
  const auto nnz = static_cast<Index>(m_inner.size());
  if (reduced.rows() != num_free() || reduced.cols() != num_free() || !reduced.isCompressed() ||
      reduced.nonZeros() != nnz ||
      !std::equal(m_outer.begin(), m_outer.end(), reduced.outerIndexPtr())) {
    // The reduced pattern; its values are all written below.
    reduced.resize(num_free(), num_free());
    reduced.resizeNonZeros(nnz);
    std::copy(m_outer.begin(), m_outer.end(), reduced.outerIndexPtr());
    int* inner = reduced.innerIndexPtr();
    tbb::parallel_for(
        tbb::blocked_range<Index>(0, nnz, 65536), [&](const tbb::blocked_range<Index>& r) {
          std::copy(m_inner.begin() + r.begin(), m_inner.begin() + r.end(), inner + r.begin());
        });
  }
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
