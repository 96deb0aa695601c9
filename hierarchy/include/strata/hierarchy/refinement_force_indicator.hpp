#pragma once
/// \file refinement_force_indicator.hpp
/// The primary refinement indicator: refine where force magnitudes are large — where the force
/// carried through the elements, or applied to the vertices, is concentrated compared with the
/// body's typical stress.
///
/// Measure. Forces become scale-free as force densities (force per area, Pa) divided by a
/// body-wide stress scale:
///
///     η_t = max( ‖σ_t‖_F ,  max_{v ∈ t} |g_v| / c_v ) / s_ref
///
/// - ‖σ_t‖_F, the element's force density: by the lecture's recipe the element pulls on its
///   vertices with its face tractions σ·n·A, so per unit area its forces are |σ n| ≤ ‖σ‖_F. The
///   Frobenius norm is rotation invariant and does not depend on the tet's shape.
/// - |g_v| / c_v, the applied-load density at a vertex of the tet: g_v = f_v − m_v ā is the
///   external force minus the vertex's share of the body's mean acceleration
///   ā = Σ_u f_u / Σ_u m_u. Gravity (any load proportional to mass) cancels exactly: self-weight
///   is never localised. c_v = Σ_{t ∋ v} A_t,opp(v) / 3 [m²] (deformed areas of the faces
///   opposite v) is the area through which the elements around v carry force to v: with a uniform
///   stress σ each element pulls on v with σ N_opp/3, so a load in equilibrium with a uniform
///   stress field has |f_v| ≤ ‖σ‖_F c_v. Loads enter through `external_forces`, so a small loaded
///   patch inside a coarse tet (no coarse vertex in it) pulls on that tet's vertices through its
///   barycentric weights and is seen even before the body has responded.
/// - τ_t, the finest-level load traction inside the tet (CutState::finest_load_traction, when the
///   driver supplies it; else 0): it enters like the load density, η_t = max(‖σ_t‖_F, |g_v|/c_v,
///   τ_t) / s_ref. Unlike |g_v|/c_v it does not shrink on a coarse cut, so a small, strongly loaded
///   patch keeps its tets refining down to the finest level even after the body's stresses have
///   built up (a uniform traction equal to the stress it causes still gives η ≈ 1).
/// - s_ref = max(S_σ, S_load, floor · E), the body's stress scale [Pa]:
///   S_σ = √(Σ_t V_t ‖σ_t‖_F² / Σ V_t), the volume-RMS stress (refinement_indicator.hpp);
///   S_load = √(Σ_v |g_v|² / c_v / A_∂), the RMS traction the loads would exert if spread over the
///   whole body surface A_∂ (rest boundary area of the coarse mesh, cached per tree) — the scale
///   that matters before stresses have built up; floor · E keeps η finite in an unloaded,
///   unstressed body
///   (`stress_floor` relative to Young's modulus, default 1e-6: strains below a microstrain never
///   drive refinement).
///
/// Why this measure: it is dimensionless and invariant under scaling lengths, E and the loads
/// together (a 1 m beam and a 10 cm armadillo with the same strains get the same η), so one
/// threshold serves every scene. A uniform stress field gives η ≤ 1 everywhere (‖σ_t‖_F = S_σ,
/// and its tractions have density ≤ ‖σ‖_F), so a threshold above 1 never refines it; a
/// concentrated load gives η ≫ 1 near it, growing as the patch shrinks relative to the body.
/// Rejected alternatives: the ratio of a vertex force to its share of gravity depends on the size
/// and on g (undefined without gravity); raw nodal forces scale with the element size; a residual
/// f_int + f_ext vanishes at equilibrium, exactly where a static load is concentrated.
#include <mutex>

#include "strata/hierarchy/refinement_indicator.hpp"

namespace strata {

/// The stress scale s_ref of the force indicator and its parts [Pa].
struct ForceReference {
  double stress_rms = 0.0;  ///< S_σ
  double load_rms = 0.0;    ///< S_load
  double floor = 0.0;       ///< stress_floor · E
  double scale = 0.0;       ///< s_ref = max of the three
};

class ForceIndicator final : public RefinementIndicator {
 public:
  /// `stress_floor` relative to Young's modulus (> 0; throws InputError otherwise).
  explicit ForceIndicator(double stress_floor = 1e-6);

  std::string name() const override { return "force"; }
  void evaluate(const CutState& state, VectorXd& eta) const override;

  /// The stress scale of `state` (the denominator of η).
  ForceReference reference(const CutState& state) const;

  /// c_v = Σ_{t ∋ v} A_t,opp(v) / 3 per vertex (#V) [m²] at `positions` (3·#V).
  static VectorXd vertex_force_areas(ConstRef<MatrixX4i> tets, ConstRef<VectorXd> positions);

  /// g_v = f_v − m_v ā with ā = Σ f / Σ m: the external forces without their mass-proportional
  /// part (3·#V) [N].
  static VectorXd localised_loads(ConstRef<VectorXd> external_forces,
                                  ConstRef<VectorXd> vertex_mass);

  /// Rest surface area of the body [m²]: the boundary of the tree's roots (the coarse mesh).
  /// O(#roots log #roots).
  static double body_surface_area(const TetTree& tree);

 private:
  /// A_∂ of `tree`, computed once per coarse mesh (keyed by the tree's address, sizes and a
  /// checksum of the coarse vertices) and reused, since the coarse mesh never changes.
  double cached_surface_area(const TetTree& tree) const;

  struct SurfaceCache {
    const TetTree* tree = nullptr;
    Index num_roots = 0;
    double checksum = 0.0;
    double area = 0.0;
  };

  double m_stress_floor;
  mutable std::mutex m_cache_mutex;
  mutable SurfaceCache m_cache;
};

}  // namespace strata
