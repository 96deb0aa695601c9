#pragma once
/// \file spring_set.hpp
/// Linear springs between vertex pairs: E = Σ ½ k (L − L₀)², L = |x_b − x_a|. The common mechanics
/// of the surface springs (surface_springs.hpp) and the skeleton-spring body (spring_body.hpp).
#include <array>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct SpringSet {
  std::vector<std::array<int, 2>> edges;  ///< vertex pairs
  VectorXd rest;                          ///< L₀ per spring [m]
  VectorXd stiffness;                     ///< k per spring [N/m]

  Index size() const { return static_cast<Index>(edges.size()); }
  /// Σ ½ k (L − L₀)² at positions x (3·#V) [J].
  double energy(ConstRef<VectorXd> x) const;
  /// f += scale · (−∂E/∂x) (scale −1 adds the gradient).
  void add_forces(ConstRef<VectorXd> x, VectorXd& f, double scale = 1.0) const;
  /// H += ∂²E/∂x²: k [n nᵀ + (1 − L₀/L)(I − n nᵀ)] per spring; with `project_psd` the second
  /// factor is clamped at 0. H must hold every spring's vertex blocks.
  void add_hessian(ConstRef<VectorXd> x, SparseMatrixd& hessian, bool project_psd) const;
  /// The 3×3 blocks (a, a), (a, b), (b, a), (b, b) of every spring as zero triplets, for a pattern.
  void add_pattern(std::vector<Eigen::Triplet<double>>& triplets) const;

 private:
  /// Value offsets of every spring's 36 Hessian entries in the last pattern add_hessian saw
  /// (found by binary search once per pattern, checked against its row indices on every use).
  /// A cache behind a const method: one SpringSet's add_hessian is not called concurrently.
  mutable std::vector<int> m_offsets;
  bool locate(const SparseMatrixd& hessian) const;
};

}  // namespace strata
