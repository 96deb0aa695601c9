// Review checks of the adaptive driver against independent computations: a static adaptive run
// equals a direct solve on its final cut (prescribed displacement, roller support, loaded patch).
#include <gtest/gtest.h>

#include "adaptive_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/region.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/finest_level.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {
namespace {

HierarchySettings adaptive_from_coarse(int levels) {
  HierarchySettings settings;
  settings.levels = levels;
  settings.mode = HierarchyMode::adaptive;
  settings.level = 0;
  settings.indicator = "force";  // the periodic driver's mechanics (see adaptive_test_utils.hpp)
  settings.in_step_refinement = false;
  settings.initial_adaptation = false;
  return settings;
}

/// A slab on a roller (z only) at the bottom, fixed on the face x = 0, its top pushed down by a
/// prescribed displacement on a strip and pressed by a small loaded patch elsewhere.
struct RollerSlab {
  TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 1, 0.25), {4, 4, 1});
  std::vector<DirichletSpec> groups;
  std::vector<RegionLoad> loads = {testing::box_load(
      Vector3d(0.6, 0.4, 0.25), Vector3d(0.75, 0.6, 0.25), Vector3d(0, 0, -400.0))};

  RollerSlab() {
    DirichletSpec roller = testing::fixed_plane("roller.0", Vector3d::Zero(), Vector3d::UnitZ());
    roller.components = {false, false, true};
    groups.push_back(roller);
    groups.push_back(testing::fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitX()));
    DirichletSpec push;
    push.name = "prescribed.0";
    push.region = BoxRegion{Vector3d(0.25, 0, 0.25), Vector3d(0.5, 1, 0.25)};
    push.kind = DirichletKind::displacement;
    push.displacement = Vector3d(0, 0, -0.004);
    groups.push_back(push);
  }
};

TEST(ReviewAdaptiveSimulation, StaticAdaptiveRunEqualsADirectSolveOnItsFinalCut) {
  const RollerSlab slab;
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 3;
  AdaptiveSimulation adaptive(
      slab.coarse, adaptive_from_coarse(2),
      {.material = testing::rubber(), .dirichlet = slab.groups, .loads = slab.loads}, settings);
  while (!adaptive.finished())
    adaptive.advance();
  ASSERT_FALSE(adaptive.changes().empty());
  ASSERT_GT(adaptive.constraints().num_hanging(), 0);

  // Independent path: core's Simulation on the final cut with the same embedding and the same
  // finest-level loads, solved along the whole load path without any restart.
  const FlatTreeMesh& flat = adaptive.flat();
  const std::vector<PointLoad> point_loads =
      finest_level_loads(adaptive.tree(), slab.loads, region_tolerance(slab.coarse.vertices));
  SimulationOptions options;
  options.vertex_embedding = adaptive.constraints().matrix();
  options.dof_vertices = adaptive.constraints().free_vertices();
  options.extra_mesh_forces = map_point_loads(adaptive.cut(), flat, point_loads);
  Simulation direct(flat.mesh, {.material = testing::rubber(), .dirichlet = slab.groups}, settings,
                    options);
  while (!direct.finished())
    direct.advance();

  const VectorXd& x = adaptive.simulation().positions();
  const VectorXd& rest = adaptive.simulation().model().rest_positions();
  const double scale = (direct.positions() - rest).lpNorm<Eigen::Infinity>();
  ASSERT_GT(scale, 1e-3);
  EXPECT_LT((x - direct.positions()).lpNorm<Eigen::Infinity>(), 1e-7 * scale);

  // The roller and the prescribed patch hold on every mesh vertex, hanging ones included.
  for (Index v = 0; v < flat.mesh.vertices.rows(); ++v) {
    const Vector3d X = flat.mesh.vertices.row(v).transpose();
    const Vector3d u = x.segment<3>(3 * v) - X;
    if (X.x() == 0.0) {
      EXPECT_LT(u.norm(), 1e-14) << "vertex " << v;
    }
    if (X.z() == 0.0) {
      EXPECT_LT(std::abs(u.z()), 1e-14) << "vertex " << v;
    }
    if (X.z() == 0.25 && X.x() >= 0.25 && X.x() <= 0.5) {
      EXPECT_LT((u - Vector3d(0, 0, -0.004)).norm(), 1e-14) << "vertex " << v;
    }
  }
  // The roller's reaction has no tangential part, and balances with the others: Σ R + f = 0.
  const std::vector<GroupReaction> reactions = adaptive.simulation().reactions();
  ASSERT_EQ(reactions.size(), 3u);
  EXPECT_EQ(reactions[0].force.x(), 0.0);
  EXPECT_EQ(reactions[0].force.y(), 0.0);
  Vector3d total = slab.loads[0].total_force;
  for (const GroupReaction& reaction : reactions)
    total += reaction.force;
  EXPECT_LT(total.norm(), 1e-6 * slab.loads[0].total_force.norm());
}

}  // namespace
}  // namespace strata
