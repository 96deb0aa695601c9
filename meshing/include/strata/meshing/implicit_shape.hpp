#pragma once
/// \file implicit_shape.hpp
/// A solid described by implicit primitives combined with CSG (the scene key
/// "mesh": {"implicit": ...}), turned into a level set by the LevelSet primitives and CSG.
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/meshing/level_set.hpp"

namespace strata {

/// A node of a CSG tree. Primitives use the fields named beside their kind; CSG nodes use
/// `operands`. Lengths in [m].
struct ImplicitShape {
  enum class Kind {
    sphere,        ///< center, radius
    box,           ///< min, max (axis-aligned)
    capsule,       ///< a, b, radius: points within radius of the segment [a, b]
    torus,         ///< center, axis, major_radius, minor_radius
    union_of,      ///< operands (≥ 1): min φ
    intersection,  ///< operands (≥ 1): max φ
    difference     ///< operands (exactly 2): the first minus the second, max(φ0, −φ1)
  };
  Kind kind = Kind::sphere;
  Vector3d center = Vector3d::Zero();
  double radius = 0.0;
  Vector3d min = Vector3d::Zero();
  Vector3d max = Vector3d::Zero();
  Vector3d a = Vector3d::Zero();
  Vector3d b = Vector3d::Zero();
  Vector3d axis = Vector3d::UnitZ();  ///< torus axis (normalised when used)
  double major_radius = 0.0;          ///< torus: radius of the tube's centre circle
  double minor_radius = 0.0;          ///< torus: tube radius
  std::vector<ImplicitShape> operands;

  static ImplicitShape sphere(const Vector3d& center, double radius);
  static ImplicitShape box(const Vector3d& min, const Vector3d& max);
  static ImplicitShape capsule(const Vector3d& a, const Vector3d& b, double radius);
  static ImplicitShape torus(const Vector3d& center, const Vector3d& axis, double major_radius,
                             double minor_radius);
  static ImplicitShape csg(Kind kind, std::vector<ImplicitShape> operands);
};

/// The shape's level set on voxels of `options.voxel_size` (all grids share one transform, so CSG
/// applies): primitives by level_set_sphere / _box / _capsule / _torus, CSG nodes fold their
/// operands left to right with csg_union / csg_intersection / csg_difference. InputError for an
/// empty CSG node, a difference without exactly 2 operands, or a bad primitive.
LevelSet implicit_shape_level_set(const ImplicitShape& shape, const LevelSetOptions& options);

/// Canonical one-line text of the shape, every number round-trip exact, e.g.
/// "union(sphere([0,0,0],1),box([0,0,0],[1,1,1]))": equal shapes give equal text (cache keys).
std::string describe_implicit_shape(const ImplicitShape& shape);

}  // namespace strata
