#pragma once
/// \file surface_springs.hpp
/// The lecture's cheap plasticity: sparse springs along the body's surface whose rest lengths
/// yield, so that a bent body keeps part of its shape after the load is gone.
///
/// Springs lie on a share of the boundary edges of the tet mesh (each edge drawn with probability
/// `fraction`, reproducibly from `seed`). A spring of rest length L₀ has stiffness k = E_s L₀ (a
/// bar of modulus E_s and cross-section L₀², so the network's stiffness does not depend on the
/// resolution) and energy ½ k (L − L₀)². After every step a spring stretched or compressed beyond
/// the yield strain ε_y takes a new rest length L₀ ← L / (1 ± ε_y) (perfectly plastic; k is kept).
/// The springs add to the elastic body: unloaded, body and springs settle between the rest shape
/// and the deformed one.
///
/// Boundary edges are tet edges, so the springs' Hessian lies in the elastic stiffness pattern.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/spring_set.hpp"

namespace strata {

/// Scene `material.surface_springs`.
struct SurfaceSpringSettings {
  double youngs_modulus = 0.0;  ///< E_s [Pa] > 0: k = E_s L₀
  /// ε_y > 0; infinity: elastic springs.
  double yield_strain = std::numeric_limits<double>::infinity();
  double fraction = 1.0;  ///< share of boundary edges with a spring, (0, 1]
  std::uint32_t seed = 1;
};

/// Throws InputError naming `where` unless E_s > 0 finite, ε_y > 0, fraction ∈ (0, 1].
void validate_surface_springs(const SurfaceSpringSettings& settings, const std::string& where);

class SurfaceSprings {
 public:
  /// Springs on the boundary edges of `boundary` (#F × 3 triangles) over rest positions
  /// (#V × 3). At least one spring is kept.
  SurfaceSprings(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                 const SurfaceSpringSettings& settings);

  Index size() const { return m_set.size(); }
  const std::vector<std::array<int, 2>>& edges() const { return m_set.edges; }
  const VectorXd& rest_lengths() const { return m_set.rest; }
  const VectorXd& stiffness() const { return m_set.stiffness; }
  /// The springs as they stand (rest lengths after yielding).
  const SpringSet& springs() const { return m_set; }

  /// Σ ½ k (L − L₀)² at positions x (3·#V) [J].
  double energy(ConstRef<VectorXd> x) const { return m_set.energy(x); }
  /// f += scale · (−∂E/∂x) (scale −1 adds the gradient).
  void add_forces(ConstRef<VectorXd> x, VectorXd& f, double scale = 1.0) const {
    m_set.add_forces(x, f, scale);
  }
  /// H += ∂²E/∂x² (SpringSet::add_hessian). H must hold every spring's vertex blocks.
  void add_hessian(ConstRef<VectorXd> x, SparseMatrixd& hessian, bool project_psd) const {
    m_set.add_hessian(x, hessian, project_psd);
  }

  /// Rest lengths follow where |L/L₀ − 1| > ε_y; returns how many springs yielded.
  Index yield(ConstRef<VectorXd> x);
  /// Yield events so far.
  long long yield_events() const { return m_yield_events; }
  /// Largest |log(L₀ / L₀ at the start)| over the springs: their plastic strain.
  double largest_plastic_strain() const;

 private:
  SurfaceSpringSettings m_settings;
  SpringSet m_set;
  VectorXd m_initial_rest;
  long long m_yield_events = 0;
};

}  // namespace strata
