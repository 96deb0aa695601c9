#include "strata/core/sim/dof_reduction.hpp"

#include "strata/core/common/error.hpp"

namespace strata {

DofReduction::DofReduction(const SparseMatrixd& pattern, const std::vector<char>& constrained) {
  STRATA_VERIFY(pattern.isCompressed() && pattern.rows() == pattern.cols() &&
                    static_cast<size_t>(pattern.rows()) == constrained.size(),
                "DofReduction: pattern must be compressed, square and match the DOF mask");
  std::vector<Index> reduced_index(constrained.size(), -1);
  for (size_t i = 0; i < constrained.size(); ++i) {
    if (constrained[i]) continue;
    reduced_index[i] = static_cast<Index>(m_free.size());
    m_free.push_back(static_cast<Index>(i));
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index col = 0; col < pattern.outerSize(); ++col) {
    if (reduced_index[col] < 0) continue;
    for (SparseMatrixd::InnerIterator it(pattern, col); it; ++it) {
      if (reduced_index[it.row()] < 0) continue;
      // Store the full value index (+1, so no value is zero) to recover the map after compression.
      const Index value_index = &it.valueRef() - pattern.valuePtr();
      triplets.emplace_back(reduced_index[it.row()], reduced_index[col],
                            static_cast<double>(value_index + 1));
    }
  }
  m_reduced_pattern.resize(num_free(), num_free());
  m_reduced_pattern.setFromTriplets(triplets.begin(), triplets.end());
  m_reduced_pattern.makeCompressed();
  m_source.resize(m_reduced_pattern.nonZeros());
  for (Index k = 0; k < m_reduced_pattern.nonZeros(); ++k) {
    m_source[k] = static_cast<Index>(m_reduced_pattern.valuePtr()[k]) - 1;
    m_reduced_pattern.valuePtr()[k] = 0.0;
  }
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
  for (size_t k = 0; k < m_source.size(); ++k)
    values[k] = source[m_source[k]];
}

}  // namespace strata
