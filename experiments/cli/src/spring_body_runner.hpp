#pragma once
/// \file spring_body_runner.hpp
/// Runs a scene whose "body" is skeleton springs (spring_body.hpp): skeletonizes mesh.surface
/// (curve_skeleton.hpp), builds the springs and steps to the end, writing probes.csv,
/// reactions.csv, stats.json and (output.vtk) `<stem>.pvd` with the surface (part 0) and the
/// skeleton (part 1) as .vtp frames.
#include <vector>

#include "strata/app/scene_runner.hpp"
#include "strata/core/sim/obstacle.hpp"

namespace strata::app::detail {

RunSummary run_spring_body_scene(const Scene& scene, const RunOptions& options);

/// The scene's obstacles: `ground` first (a plane obstacle named "ground"), then `obstacles`:
/// planes in closed form, the others as level sets (implicit shapes and surfaces voxelised at
/// `voxel_size`, default half of `mean_edge`, the body's mean edge length).
std::vector<Obstacle> build_obstacles(const Scene& scene, double mean_edge);

}  // namespace strata::app::detail
