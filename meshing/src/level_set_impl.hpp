#pragma once
/// \file level_set_impl.hpp
/// The OpenVDB grid behind `LevelSet` (private to the meshing library: only level_set*.cpp include
/// this header).
#include <openvdb/openvdb.h>

#include "strata/meshing/level_set.hpp"

namespace strata {

struct LevelSet::Impl {
  explicit Impl(openvdb::FloatGrid::Ptr level_set);
  openvdb::FloatGrid::Ptr grid;  ///< never null; GRID_LEVEL_SET with a uniform linear transform
  /// Index box outside which every voxel holds the background: the leaves' box and that of every
  /// tile whose value differs from the background (empty for an empty grid).
  openvdb::CoordBBox extent;
};

namespace detail {

/// openvdb::initialize() once per process (thread-safe).
void ensure_openvdb_initialized();

/// A LevelSet owning `grid` (marks it as a level set).
LevelSet wrap_level_set(openvdb::FloatGrid::Ptr grid);

/// Checks a voxel size and half width; InputError naming `what` otherwise.
void check_level_set_options(const LevelSetOptions& options, const std::string& what);
/// InputError naming `what` when a narrow band around a surface in the box [lo, hi] would hold
/// more voxels than a level set here may (about the box's surface area / voxel² × band width).
void check_level_set_size(const Vector3d& lo, const Vector3d& hi, const LevelSetOptions& options,
                          const std::string& what);

}  // namespace detail
}  // namespace strata
