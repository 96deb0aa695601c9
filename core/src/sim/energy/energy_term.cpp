#include "strata/core/sim/energy/energy_term.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "strata/core/common/error.hpp"
#include "strata/core/common/vector_chunks.hpp"

namespace strata {

EnergyTerm& EnergySum::add(std::unique_ptr<EnergyTerm> term) {
  STRATA_VERIFY(term != nullptr, "EnergySum::add: null term");
  m_terms.push_back(std::move(term));
  return *m_terms.back();
}

double EnergySum::value(ConstRef<VectorXd> q) const {
  double total = 0.0;
  for (const auto& term : m_terms) {
    const double e = term->value(q);
    if (!std::isfinite(e)) return std::numeric_limits<double>::infinity();
    total += e;
  }
  return total;
}

double EnergySum::max_step(ConstRef<VectorXd> q, ConstRef<VectorXd> step) const {
  double alpha = 1.0;
  for (const auto& term : m_terms)
    alpha = std::min(alpha, term->max_step(q, step));
  return alpha;
}

void EnergySum::gradient(ConstRef<VectorXd> q, VectorXd& gradient) const {
  gradient.setZero(q.size());
  for (const auto& term : m_terms)
    term->add_gradient(q, gradient);
}

void EnergySum::hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const {
  if (hessian.rows() != m_pattern->rows() || hessian.nonZeros() != m_pattern->nonZeros())
    hessian = *m_pattern;
  // One of the first two terms writes H if it can; the others add in order.
  const std::size_t none = m_terms.size();
  std::size_t setter = none;
  for (std::size_t i = 0; i < std::min<std::size_t>(2, m_terms.size()) && setter == none; ++i)
    if (m_terms[i]->set_hessian(q, hessian, project_psd)) setter = i;
  if (setter == none) std::fill(hessian.valuePtr(), hessian.valuePtr() + hessian.nonZeros(), 0.0);
  for (std::size_t i = 0; i < m_terms.size(); ++i)
    if (i != setter) m_terms[i]->add_hessian(q, hessian, project_psd);
}

void add_values_same_pattern(const SparseMatrixd& source, double scale, SparseMatrixd& target) {
  STRATA_VERIFY(source.nonZeros() == target.nonZeros() && source.rows() == target.rows(),
                "add_values_same_pattern: patterns differ");
  Eigen::Map<VectorXd>(target.valuePtr(), target.nonZeros()) +=
      scale * Eigen::Map<const VectorXd>(source.valuePtr(), source.nonZeros());
}

void add_diagonal(ConstRef<VectorXd> weights, SparseMatrixd& target) {
  STRATA_VERIFY(weights.size() == target.rows(), "add_diagonal: size mismatch");
  for (Index i = 0; i < target.outerSize(); ++i) {
    const int* begin = target.innerIndexPtr() + target.outerIndexPtr()[i];
    const int* end = target.innerIndexPtr() + target.outerIndexPtr()[i + 1];
    const int* found = std::lower_bound(begin, end, static_cast<int>(i));
    STRATA_VERIFY(found != end && *found == i, "add_diagonal: pattern lacks a diagonal entry");
    target.valuePtr()[found - target.innerIndexPtr()] += weights[i];
  }
}

void DiagonalPositions::add(double scale, ConstRef<VectorXd> weights, SparseMatrixd& target) {
  STRATA_VERIFY(weights.size() == target.rows() && target.isCompressed(),
                "DiagonalPositions::add: size mismatch or uncompressed matrix");
  const int* outer = target.outerIndexPtr();
  const int* inner = target.innerIndexPtr();
  // Kept while they are still the diagonal's in this matrix's index arrays, whichever matrix it
  // is (Eigen also reuses arrays for another pattern of the same size on assignment).
  bool cached = target.rows() == m_size && target.nonZeros() == m_non_zeros;
  if (cached)
    cached = sum_over_vector_chunks(m_size, [&](Index begin, Index end) {
               for (Index i = begin; i < end; ++i)
                 if (!(m_positions[i] >= outer[i] && m_positions[i] < outer[i + 1] &&
                       inner[m_positions[i]] == i))
                   return 1.0;
               return 0.0;
             }) == 0.0;
  if (!cached) {
    std::vector<Index> positions(target.outerSize());
    for (Index i = 0; i < target.outerSize(); ++i) {
      const int* begin = inner + outer[i];
      const int* end = inner + outer[i + 1];
      const int* found = std::lower_bound(begin, end, static_cast<int>(i));
      STRATA_VERIFY(found != end && *found == i,
                    "DiagonalPositions::add: pattern lacks a diagonal entry");
      positions[i] = found - inner;
    }
    m_positions = std::move(positions);  // committed only once the whole diagonal is found
    m_size = target.rows();
    m_non_zeros = target.nonZeros();
  }
  // The products are rounded before the sums (no fused multiply-add): the values are those of
  // add_diagonal, and a term's additions commute with the other terms' as EnergySum assumes.
  m_scaled.resize(m_size);
  double* values = target.valuePtr();
  for_each_vector_chunk(m_size, [&](Index begin, Index end) {
    m_scaled.segment(begin, end - begin) = scale * weights.segment(begin, end - begin);
    for (Index i = begin; i < end; ++i)
      values[m_positions[i]] += m_scaled[i];
  });
}

}  // namespace strata
