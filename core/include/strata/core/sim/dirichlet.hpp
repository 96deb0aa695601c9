#pragma once
/// \file dirichlet.hpp
/// Dirichlet (prescribed-motion) vertex groups, scaled by a factor s: by default in dynamic runs
/// s = t / ramp_time (clamped at 1), in static runs s is the load factor; a group with an
/// `amplitude` table follows s(t) of that table instead (amplitude.hpp; t is the load factor in
/// static runs).
///
/// Kinds, for a vertex with rest position X:
/// - fixed: u = 0, target x = X.
/// - displacement: u = s·d, target x = X + s·d.
/// - rotation: rigid rotation by φ = s·angle about `axis` through `center` (Rodrigues),
///   target x = c + R(φ)(X − c).
///
/// `components` restricts a group to some coordinates (e.g. {true, false, false}: only x is
/// prescribed, y and z stay free — a roller support); the default prescribes all three.
///
/// Overlap rule: a vertex selected by several groups belongs to the LAST group that selects it
/// (later groups win); earlier groups keep their other vertices. A group left with no vertex is an
/// InputError naming it.
#include <array>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/sim/amplitude.hpp"
#include "strata/core/sim/region.hpp"

namespace strata {

enum class DirichletKind { fixed, displacement, rotation };

/// A Dirichlet group as written in a scene.
struct DirichletSpec {
  std::string name;  ///< for messages and reports, e.g. "fixed[1]"
  Region region;
  DirichletKind kind = DirichletKind::fixed;
  Vector3d displacement = Vector3d::Zero();  ///< d [m] (displacement)
  Vector3d axis = Vector3d::UnitZ();         ///< rotation axis (rotation; any non-zero length)
  double angle = 0.0;                        ///< total rotation angle [rad] (rotation)
  bool has_center = false;                   ///< rotation center given?
  Vector3d center = Vector3d::Zero();        ///< rotation center [m] (rotation, if has_center)
  std::array<bool, 3> components = {true, true, true};  ///< prescribed coordinates x, y, z
  Amplitude amplitude;  ///< load history s(t); empty: the run's default ramp
};

/// A group resolved against a mesh: its vertices and moment center.
struct DirichletGroup {
  DirichletSpec spec;
  std::vector<int> vertices;  ///< vertices this group owns (after the overlap rule), ascending
  /// Point about which reaction moments are reported: the rotation center if given, else the
  /// rest centroid of the group's vertices.
  Vector3d moment_center = Vector3d::Zero();

  /// The group's factor at time t: its amplitude s(t), or `default_s` without one.
  double factor(double t, double default_s) const;
  /// ds/dt at time t: the amplitude's slope, or `default_rate` without one.
  double factor_rate(double t, double default_rate) const;
  /// Target position of a vertex with rest position X at ramp factor s.
  Vector3d target_position(const Vector3d& X, double s) const;
  /// Target velocity dx/dt given ds/dt.
  Vector3d target_velocity(const Vector3d& X, double s, double ds_dt) const;
  /// Target acceleration d²x/dt² for a linear ramp (d²s/dt² = 0).
  Vector3d target_acceleration(const Vector3d& X, double s, double ds_dt) const;
};

/// Resolves the specs against rest positions (#V × 3) with the region tolerance `tolerance` [m].
/// Throws InputError naming the group for a malformed region, a zero rotation axis, or a group
/// that selects no vertex ("fixed[1]: region selects no vertex").
std::vector<DirichletGroup> resolve_dirichlet_groups(const std::vector<DirichletSpec>& specs,
                                                     ConstRef<MatrixX3d> rest_positions,
                                                     double tolerance);

/// Per-vertex owning group index (−1 for free vertices); #V entries.
VectorXi dirichlet_owner(const std::vector<DirichletGroup>& groups, Index num_vertices);

/// Per-DOF constrained flag (3·#V entries, 1 = prescribed; only the groups' components).
std::vector<char> dirichlet_dof_mask(const std::vector<DirichletGroup>& groups, Index num_vertices);

/// How many independent rigid motions (of the 3 translations and 3 rotations) the groups leave
/// free: 0 when the prescribed coordinates pin the body, 3 for a single fixed vertex (it still
/// turns about it), 1 for fixed vertices on one line. A static run needs 0 unless contact or
/// balanced loads hold the body. `rest` is 3·#V.
int free_rigid_motions(const std::vector<DirichletGroup>& groups, ConstRef<VectorXd> rest);

/// Writes the target positions and velocities at time t of all constrained DOFs into `x` and `v`
/// (3·#V each); free DOFs are left untouched. `rest` is 3·#V. Groups without an amplitude use the
/// factor `default_s` and its rate `default_rate`.
void apply_dirichlet(const std::vector<DirichletGroup>& groups, ConstRef<VectorXd> rest, double t,
                     double default_s, double default_rate, VectorXd& x, VectorXd& v);

}  // namespace strata
