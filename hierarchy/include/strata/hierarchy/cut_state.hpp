#pragma once
/// \file cut_state.hpp
/// What a refinement criterion sees of the simulation on an active cut: the flattened cut, its
/// deformed positions, per-tet stresses, the applied loads and masses. The adaptive driver fills
/// one after a step; the indicators (refinement_indicator.hpp) and the controller
/// (refinement_controller.hpp) only read it.
#include "strata/core/common/types.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/hierarchy/tet_tree.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {

struct RecoveryEstimate;
struct RecoveryGeometry;

/// A snapshot of the simulation on the flattened active cut `flat` of `tree` (#V vertices,
/// #T tets). The referenced objects and the viewed vectors must outlive the snapshot.
///
/// The vectors are `Eigen::Ref<const VectorXd>` views held by value rather than `ConstRef`
/// (`const Ref&`): a reference member would bind to a temporary Ref made from the caller's
/// VectorXd, which dies at the end of the statement unless the CutState is a braced local.
struct CutState {
  const TetTree& tree;
  /// The flattened active cut: flat.mesh (rest, #V × 3, #T × 4), flat.tet_nodes (#T).
  const FlatTreeMesh& flat;
  /// 3·#V deformed positions of the flat vertices [m] (hanging ones included, x = C q).
  Eigen::Ref<const VectorXd> positions;
  /// ElasticModel::tet_fields(positions): per flat tet Green strain, Cauchy stress (Voigt
  /// [xx yy zz xy yz xz], Pa), von Mises.
  const TetFields& fields;
  /// 3·#V dead loads on the flat vertices [N]: gravity plus region loads, loads defined on the
  /// finest level mapped onto the flat vertices through barycentric weights.
  Eigen::Ref<const VectorXd> external_forces;
  /// #V lumped vertex masses [kg].
  Eigen::Ref<const VectorXd> vertex_mass;
  const Material& material;
  /// The driver's step counter (for the controller's hysteresis in steps).
  long step = 0;
  /// Optional, #T: per flat tet the largest traction [Pa] of the finest-level loads acting inside
  /// it (|f_i| / a_i of each loaded finest vertex i embedded in the tet, a_i its share of the
  /// loaded surface area; 0 where no load acts). Lets the force indicator see how concentrated a
  /// load is at the finest level, which the flat vertices' forces smear over coarse tets. Null:
  /// only `external_forces` are used.
  const VectorXd* finest_load_traction = nullptr;
  /// Optional: the squared energy norm ‖u‖_E² [J] the error estimate is relative to — the largest
  /// over the run so far, so that the first small-strain steps of a run are not judged relative
  /// to their own tiny deformation. 0: the state's own.
  double solution_energy_scale = 0.0;
  /// Optional: the largest vertex displacement [m] the local error estimate is relative to — the
  /// largest over the run so far. 0: the state's own.
  double solution_displacement_scale = 0.0;
  /// Optional: the recovery estimate of this very state (refinement_recovery_estimator.hpp),
  /// when the driver has computed it already; the recovery indicator then reuses it.
  const RecoveryEstimate* recovery_estimate = nullptr;
  /// Optional: the rest geometry of `flat` the recovery estimate reads (recovery_geometry), when
  /// the driver keeps it for the cut; computed per estimate otherwise.
  const RecoveryGeometry* recovery_geometry = nullptr;
  /// The decision's tolerance is the indicator's divided by this (≥ 1): a static run whose
  /// refinement passes measured changes larger than the estimate of the cuts they refined judges
  /// later decisions by that ratio (AdaptiveSimulation, README "Error control"), and a dynamic
  /// run's in-step refinement marks against coarsen_budget · tolerance (divided by it as well).
  double tolerance_scale = 1.0;
};

}  // namespace strata
