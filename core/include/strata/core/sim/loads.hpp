#pragma once
/// \file loads.hpp
/// External dead loads (constant in time, independent of the deformation): gravity on the lumped
/// masses and total forces spread over regions. The result is a 3·#V vertex-major force vector
/// [N]; static runs scale it by the load factor.
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/region.hpp"

namespace strata {

/// A total force [N] applied to the part of the body in `region`.
struct RegionLoad {
  std::string name;  ///< for messages, e.g. "loads[0]"
  Region region;
  Vector3d total_force = Vector3d::Zero();
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

/// Total external force vector (3·#V): gravity plus every region load, regions selected in the
/// rest positions (#V × 3) with `tolerance` [m]. Throws InputError naming a load whose region is
/// malformed, selects no vertex, or whose force is not finite.
VectorXd external_forces(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                         ConstRef<VectorXd> vertex_mass, const Vector3d& gravity,
                         const std::vector<RegionLoad>& loads, double tolerance);

}  // namespace strata
