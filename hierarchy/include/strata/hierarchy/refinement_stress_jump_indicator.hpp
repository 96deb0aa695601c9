#pragma once
/// \file refinement_stress_jump_indicator.hpp
/// Alternative indicator for comparison (Kelly-type, after Kelly, Gago, Zienkiewicz, Babuška
/// 1983): the jump of the traction across the faces of a tet,
///
///     η_t = Σ_f |(σ_t − σ_nb(f)) · N_f|  /  (s_ref · Σ_f A_f),
///
/// with N_f the deformed area normal of face f (|N_f| = A_f), σ_nb(f) the Cauchy stress of the
/// active tet across f, and s_ref = max(S_σ, stress_floor · E) (volume-RMS stress, see
/// refinement_indicator.hpp). Faces on the body's surface contribute nothing (tractions there are
/// loads, not jumps). η is the mean traction jump per unit face area relative to the body's
/// stress: dimensionless, 0 for any uniform stress field, large where the piecewise-constant
/// stress is under-resolved (a smooth gradient g gives η ~ g h / s_ref, so it falls as h does).
///
/// Neighbours: a face shared by two active tets (same three vertices) is matched through the
/// vertex-to-tet incidence; an unmatched face lying on a coarse-mesh boundary face is surface; any
/// other face (a non-conforming interface between finer and coarser active tets) is matched by
/// locating the point just outside its centroid in the tree (rest geometry), so each such face
/// samples the neighbour at its centre. Cost O(#T + #roots + #interface faces · depth).
#include "strata/hierarchy/refinement_indicator.hpp"

namespace strata {

class StressJumpIndicator final : public RefinementIndicator {
 public:
  /// `stress_floor` relative to Young's modulus (> 0; throws InputError otherwise).
  explicit StressJumpIndicator(double stress_floor = 1e-6);

  std::string name() const override { return "stress_jump"; }
  void evaluate(const CutState& state, VectorXd& eta) const override;

  /// Per flat tet and local face k (opposite vertex k), the flat tet across it, or −1 on the
  /// body's surface (#T × 4).
  static MatrixX4i face_neighbours(const CutState& state);

 private:
  double m_stress_floor;
};

}  // namespace strata
