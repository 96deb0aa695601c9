#pragma once
/// \file energy_term.hpp
/// One potential of a Problem, E_i(q), over the 3·#Q DOF vector: its value, gradient and Hessian
/// (exact or PSD-projected). Newton minimises the sum of a list of terms (EnergySum) for static
/// load steps and backward-Euler steps alike; explicit integrators use the elastic forces and the
/// loads directly.
///
/// Hessians are added into a matrix in the Problem's fixed sparsity pattern (the elastic
/// stiffness pattern, which holds every vertex's diagonal 3×3 block), so a sum of terms keeps one
/// pattern and one symbolic factorisation.
#include <memory>
#include <string_view>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  /// Short name for reports and tests ("elastic", "inertia", ...).
  virtual std::string_view name() const = 0;
  /// E(q) [J]; +inf where the term is undefined (e.g. an inverted element of a model that cannot
  /// handle inversion).
  virtual double value(ConstRef<VectorXd> q) const = 0;
  /// g += ∂E/∂q (3·#Q).
  virtual void add_gradient(ConstRef<VectorXd> q, VectorXd& gradient) const = 0;
  /// H += ∂²E/∂q², or its PSD projection when `project_psd` (per element or per vertex, so the
  /// sum stays PSD). H has the Problem's pattern; only its values change.
  virtual void add_hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian,
                           bool project_psd) const = 0;
  /// H = ∂²E/∂q² (or its PSD projection), overwriting every value of H (the Problem's pattern):
  /// for a term that assembles the whole pattern anyway, which saves the sum a zero fill and an
  /// add. Returns false (H untouched) where the term only adds.
  virtual bool set_hessian(ConstRef<VectorXd> /*q*/, SparseMatrixd& /*hessian*/,
                           bool /*project_psd*/) const {
    return false;
  }
  /// The largest α ≤ 1 for which the term is sure to stay finite along q + α Δq (a barrier's
  /// step filter); 1 for terms defined everywhere.
  virtual double max_step(ConstRef<VectorXd> /*q*/, ConstRef<VectorXd> /*step*/) const {
    return 1.0;
  }
};

/// A sum of energy terms, the objective Newton minimises. Terms are owned.
class EnergySum {
 public:
  /// `pattern`: the sparsity pattern every Hessian is assembled into (3·#Q square, compressed).
  explicit EnergySum(const SparseMatrixd& pattern) : m_pattern(&pattern) {}

  EnergyTerm& add(std::unique_ptr<EnergyTerm> term);
  template <typename Term, typename... Args>
  Term& emplace(Args&&... args) {
    return static_cast<Term&>(add(std::make_unique<Term>(std::forward<Args>(args)...)));
  }

  const std::vector<std::unique_ptr<EnergyTerm>>& terms() const { return m_terms; }
  const SparseMatrixd& pattern() const { return *m_pattern; }

  /// Σ E_i(q) [J] (+inf if any term is).
  double value(ConstRef<VectorXd> q) const;
  /// ∂E/∂q, resized to 3·#Q.
  void gradient(ConstRef<VectorXd> q, VectorXd& gradient) const;
  /// The smallest max_step of the terms.
  double max_step(ConstRef<VectorXd> q, ConstRef<VectorXd> step) const;
  /// ∂²E/∂q² in the pattern (H is set to the pattern on first use, then only its values change).
  /// The first of the first two terms that can write H does so (set_hessian), else H starts at
  /// zero; the others add in order. Since 0 + x = x and a + b = b + a, the values are the same
  /// bit for bit as a zero fill followed by adding every term in order.
  void hessian(ConstRef<VectorXd> q, SparseMatrixd& hessian, bool project_psd) const;

 private:
  const SparseMatrixd* m_pattern;
  std::vector<std::unique_ptr<EnergyTerm>> m_terms;
};

/// Adds `scale` · the values of `source` to those of `target`; both must have the same pattern.
void add_values_same_pattern(const SparseMatrixd& source, double scale, SparseMatrixd& target);

/// Adds `weights[i]` to the diagonal entry (i, i) of `target`, whose pattern must hold the
/// diagonal.
void add_diagonal(ConstRef<VectorXd> weights, SparseMatrixd& target);

/// The positions of a pattern's diagonal entries in its values, for terms that add to the
/// diagonal of every Hessian of a Problem (one pattern): found on first use and again when the
/// matrix's size or non-zero count differs or its index arrays no longer hold the diagonal at the
/// cached positions (checked on every use, one read per row).
class DiagonalPositions {
 public:
  /// Adds `scale · weights[i]` to entry (i, i) of `target`, whose pattern must hold the diagonal;
  /// the same values as add_diagonal(scale * weights, target).
  void add(double scale, ConstRef<VectorXd> weights, SparseMatrixd& target);

 private:
  std::vector<Index> m_positions;
  VectorXd m_scaled;
  Index m_size = -1;
  Index m_non_zeros = -1;
};

}  // namespace strata
