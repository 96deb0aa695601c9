#pragma once
/// \file loads.hpp
/// External dead loads (independent of the deformation): gravity on the lumped masses and total
/// forces spread over regions, as 3·#V vertex-major force vectors [N]. Loads without an amplitude
/// are constant in dynamic runs and scaled by the load factor in static runs; a load with an
/// amplitude table (amplitude.hpp) is scaled by its s(t) instead.
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/amplitude.hpp"
#include "strata/core/sim/region.hpp"

namespace strata {

/// A total force [N] applied to the part of the body in `region`.
struct RegionLoad {
  std::string name;  ///< for messages, e.g. "loads[0]"
  Region region;
  Vector3d total_force = Vector3d::Zero();
  Amplitude amplitude{};  ///< load history s(t); empty: the run's default
};

/// A force vector that follows a load history: f(t) = s(t) · forces.
struct TimedForces {
  Amplitude amplitude;  ///< not empty
  VectorXd forces;      ///< at s = 1 [N]
};

/// External loads split by history.
struct ExternalLoads {
  VectorXd base;                   ///< gravity and the loads without an amplitude, 3·#V [N]
  std::vector<TimedForces> timed;  ///< one per load with an amplitude, 3·#V each
};

/// Gravity: f_i = m_i g for the lumped vertex masses `vertex_mass` (#V) [kg] and `gravity` [m/s²].
/// 3·#V entries.
VectorXd gravity_forces(ConstRef<VectorXd> vertex_mass, const Vector3d& gravity);

/// Spreads `total_force` over the selected vertices `vertices` as a uniform traction on the
/// boundary triangles `boundary` (#F × 3) whose three vertices are all selected: triangle k gets
/// total · A_k / Σ A, a third to each of its vertices. If no boundary triangle qualifies the force
/// is split equally over the selected vertices. Adds into `forces` (3·#V). `positions` #V × 3.
/// Throws InputError naming `name` if `vertices` is empty.
void add_region_force(const std::string& name, const std::vector<int>& vertices,
                      const Vector3d& total_force, ConstRef<MatrixX3d> positions,
                      ConstRef<MatrixX3i> boundary, VectorXd& forces);

/// The external loads: gravity and every region load, regions selected in the rest positions
/// (#V × 3) with `tolerance` [m]. Throws InputError naming a load whose region is malformed,
/// selects no vertex, whose force is not finite or whose amplitude is malformed.
ExternalLoads external_loads(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                             ConstRef<VectorXd> vertex_mass, const Vector3d& gravity,
                             const std::vector<RegionLoad>& loads, double tolerance);

/// Total external force vector at full load, base + Σ timed forces at s = 1 (3·#V).
VectorXd external_forces(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                         ConstRef<VectorXd> vertex_mass, const Vector3d& gravity,
                         const std::vector<RegionLoad>& loads, double tolerance);

}  // namespace strata
