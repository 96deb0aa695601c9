#pragma once
/// \file spring_body_runner.hpp
/// Runs a scene whose "body" is skeleton springs (spring_body.hpp): skeletonizes mesh.surface
/// (curve_skeleton.hpp), builds the springs and steps to the end, writing probes.csv,
/// reactions.csv, stats.json and (output.vtk) `<stem>.pvd` with the surface (part 0) and the
/// skeleton (part 1) as .vtp frames.
#include "strata/app/scene_runner.hpp"

namespace strata::app::detail {

RunSummary run_spring_body_scene(const Scene& scene, const RunOptions& options);

}  // namespace strata::app::detail
