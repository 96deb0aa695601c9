#pragma once
/// \file level_set.hpp
/// Narrow-band signed distance fields (OpenVDB level sets behind a plain Eigen interface).
///
/// A `LevelSet` stores φ(x), the signed distance to a surface [m], negative inside, on the voxels
/// of a sparse grid within `half_width` voxels of the surface; elsewhere φ = ±background
/// (background = half_width · voxel_size). Sampling is trilinear between voxel centres, the
/// gradient is that of the same interpolant, so value and gradient are consistent.
/// OpenVDB: Museth, "VDB: High-resolution sparse volumes with dynamic topology", ACM TOG 2013.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "strata/core/common/types.hpp"
#include "strata/meshing/surface_mesh.hpp"
#include "strata/meshing/surface_topology.hpp"

namespace strata {

/// Resolution of a level set.
struct LevelSetOptions {
  double voxel_size = 0.01;  ///< edge of a cubic voxel [m], > 0
  double half_width = 3.0;   ///< narrow-band half width [voxels], ≥ 1
};

/// A narrow-band signed distance grid (value type: float). Copies are deep; moves are cheap.
/// Queries are const and may run concurrently; no method modifies a grid in place.
/// A moved-from LevelSet may only be assigned to or destroyed.
class LevelSet {
 public:
  LevelSet();  ///< an empty grid (φ = background everywhere)
  ~LevelSet();
  LevelSet(const LevelSet& other);
  LevelSet& operator=(const LevelSet& other);
  LevelSet(LevelSet&& other) noexcept;
  LevelSet& operator=(LevelSet&& other) noexcept;

  /// φ(p) [m], trilinear; ±background outside the narrow band (−inside, +outside).
  double signed_distance(const Vector3d& p) const;
  /// ∇φ(p) of the trilinear interpolant [1]; ≈ the unit outward normal inside the band, zero
  /// where all eight neighbouring voxels hold the background.
  Vector3d gradient(const Vector3d& p) const;
  /// φ and ∇φ in one lookup.
  double signed_distance_and_gradient(const Vector3d& p, Vector3d& gradient) const;
  /// φ(p) and its gradient from the tricubic Catmull-Rom interpolant of the 4 × 4 × 4 voxels
  /// around p: it passes through the voxel values, reproduces quadratic fields, and is C¹ — its
  /// gradient is continuous across voxel faces, where the trilinear one jumps. Energies built on
  /// it (obstacle contact) are then C¹ too, so Newton can reach a zero gradient where a
  /// minimiser lies on a voxel face. Exact to the voxel values within half_width − 2√3 voxels of
  /// the surface (the stencil reads up to 2√3 voxels away; farther it meets the background).
  double smooth_signed_distance_and_gradient(const Vector3d& p, Vector3d& gradient) const;

  /// World-space box (min, max) [m] of the active (narrow-band) voxels; (0, 0) when empty.
  std::pair<Vector3d, Vector3d> bounding_box() const;
  double voxel_size() const;
  double background() const;  ///< [m]
  Index num_active_voxels() const;
  std::string name() const;  ///< grid name in .vdb files

  /// Zero iso-surface (OpenVDB volume-to-mesh; quads are split into triangles). `adaptivity` in
  /// [0, 1] merges flat regions into fewer triangles.
  SurfaceMesh to_surface(double isovalue = 0.0, double adaptivity = 0.0) const;

  /// Writes the grid (as a float level-set grid named `name()`) to a .vdb file. InputError naming
  /// the file when it cannot be written.
  void write_vdb(const std::filesystem::path& path) const;
  /// Reads a float level-set grid from a .vdb: the grid named `grid_name`, or the first float
  /// grid when empty. The grid must have a uniform linear transform. InputError naming the file
  /// (and grid) when it is missing, corrupt or holds no such grid.
  static LevelSet read_vdb(const std::filesystem::path& path, const std::string& grid_name = "");

  struct Impl;  ///< the OpenVDB grid (private to the meshing library)
  explicit LevelSet(std::unique_ptr<Impl> impl);
  const Impl& impl() const { return *m_impl; }

 private:
  std::unique_ptr<Impl> m_impl;
};

/// A level set built from a surface, with what the surface check found.
struct SurfaceLevelSet {
  LevelSet level_set;
  SurfaceTopology topology;  ///< topology.watertight() false → signs come from winding numbers
};

/// Surface (#V × 3, #F × 3) → narrow-band signed distance (OpenVDB mesh-to-volume, exact
/// distance to the triangles within the band). A watertight surface takes OpenVDB's signed
/// conversion (orientation-independent flood fill). A surface with holes, non-manifold or
/// misoriented edges takes the unsigned distance, signed per band voxel by the generalized winding
/// number (inside where w > ½), which closes small holes like a soap film and tolerates
/// self-intersections; signs away from the band then follow by flood fill. Throws InputError for
/// an empty surface, non-finite coordinates or a bad voxel size.
SurfaceLevelSet surface_to_level_set(const SurfaceMesh& surface, const LevelSetOptions& options);

/// Level set of an exact signed distance function `sdf` (1-Lipschitz) whose zero set lies in the
/// box [lo, hi]. Only voxels within the band are evaluated (blocks are skipped by the Lipschitz
/// bound).
LevelSet level_set_from_function(const std::function<double(const Vector3d&)>& sdf,
                                 const Vector3d& lo, const Vector3d& hi,
                                 const LevelSetOptions& options, const std::string& name);

/// Sphere |x − center| − radius.
LevelSet level_set_sphere(const Vector3d& center, double radius, const LevelSetOptions& options);
/// Axis-aligned box [min, max] (exact distance, also at edges and corners).
LevelSet level_set_box(const Vector3d& min, const Vector3d& max, const LevelSetOptions& options);
/// Capsule: points within `radius` of the segment [a, b].
LevelSet level_set_capsule(const Vector3d& a, const Vector3d& b, double radius,
                           const LevelSetOptions& options);
/// Torus around `axis` (normalised) through `center`: tube radius `minor_radius` around the circle
/// of radius `major_radius`.
LevelSet level_set_torus(const Vector3d& center, const Vector3d& axis, double major_radius,
                         double minor_radius, const LevelSetOptions& options);

/// CSG on level sets of the same voxel size and alignment (OpenVDB csg*Copy; inputs unchanged):
/// union min(φa, φb), intersection max(φa, φb), difference max(φa, −φb). InputError when the
/// transforms differ.
LevelSet csg_union(const LevelSet& a, const LevelSet& b);
LevelSet csg_intersection(const LevelSet& a, const LevelSet& b);
LevelSet csg_difference(const LevelSet& a, const LevelSet& b);

}  // namespace strata
