// Refinement controller: decide/apply rounds with fields recomputed on every cut, as the adaptive
// driver runs them. Uniform stress, localised loads and bumps, load removal, flicker, identity.
#include <gtest/gtest.h>

#include <algorithm>

#include "refinement_rounds.hpp"

namespace strata {
namespace {

using namespace strata::test;

TEST(RefinementController, UniformStressNeverRefines) {
  TetTree tree(test::slab(), 2);
  for (const double threshold : {3.0, 1.05}) {
    RefinementSettings settings = fast_settings();
    settings.refine_threshold = threshold;
    RefinementController controller(settings);
    ActiveCut cut(tree);
    long step = 0;
    for (int r = 0; r < 5; ++r) {
      const CutChanges c = adapt_round(controller, cut, affine_scene(), step++);
      EXPECT_EQ(c.over_threshold, 0) << threshold;
    }
    EXPECT_EQ(cut.size(), tree.num_roots());
  }
}

TEST(RefinementController, RefinedUniformFieldCoarsensToTheRoots) {
  TetTree tree(test::slab(), 2);
  const ActiveCut roots(tree);
  RefinementController controller(fast_settings());
  ActiveCut cut = ActiveCut::uniform(tree, 2);
  cut.coarsen(tree.child(5, 3));  // a mixed cut: levels 1 and 2
  long step = 0;
  for (int r = 0; r < 2; ++r)
    adapt_round(controller, cut, affine_scene(), step++);
  EXPECT_EQ(cut.sorted_nodes(), roots.sorted_nodes());
}

TEST(RefinementController, LocalisedBumpRefinesOnlyNearIt) {
  TetTree tree(test::slab(), 3);
  RefinementController controller(fast_settings());
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  run_to_steady(controller, cut, scene, step, 10);
  EXPECT_EQ(cut.finest_level(), 3);
  // A small fraction of the full resolution (432 · 8³ leaves).
  EXPECT_LT(cut.size(), tree.num_roots() * 512 / 50);
  expect_refinement_near(cut, kBumpCentre, 0.3);
  // The finest tets sit where the bump moves the body: |u| > 1% of its depth for
  // r < 0.08·√ln 100 = 0.17, plus a finest tet's size (≈ 0.02).
  for (const NodeId n : cut.nodes())
    if (tree.level(n) == 3) {
      EXPECT_LT((node_centroid(tree, n) - kBumpCentre).norm(), 0.19);
    }
}

TEST(RefinementController, ConcentratedLoadRefinesOnlyNearItAndCoarsensBackWhenRemoved) {
  TetTree tree(test::slab(), 3);
  const ActiveCut roots(tree);
  RefinementSettings settings;
  settings.min_steps_between_changes = 2;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  long step = 0;
  Scene loaded;
  loaded.loads = top_point_loads();
  run_to_steady(controller, cut, loaded, step, 20);
  EXPECT_EQ(cut.finest_level(), 3);
  expect_refinement_near(cut, Vector3d(0.55, 0.55, 0.25), 0.35);
  for (const PointLoad& load : loaded.loads) {
    const TreePointLocator locator(tree);
    EXPECT_EQ(tree.level(test::active_location(cut, locator, load.point).node), 3);
  }
  // Load removed, no motion: each round merges one level once the parents have settled.
  const Scene unloaded;
  const int bound = tree.max_level() + static_cast<int>(settings.min_steps_between_changes);
  for (int r = 0; r < bound; ++r)
    adapt_round(controller, cut, unloaded, step++);
  EXPECT_EQ(cut.sorted_nodes(), roots.sorted_nodes());
}

// A small loaded patch inside one coarse tet's top face: refined down to the finest level there,
// nowhere far away.
TEST(RefinementController, PatchInsideACoarseTetRefinesThere) {
  TetTree tree(test::slab(), 3);
  RefinementController controller(fast_settings());
  ActiveCut cut(tree);
  const Vector3d centre(0.61, 0.43, 0.25);  // no coarse vertex within 0.05
  for (Index v = 0; v < tree.num_coarse_vertices(); ++v)
    ASSERT_GT((tree.vertex_position(static_cast<int>(v)) - centre).norm(), 0.05);
  Scene scene;
  for (int k = 0; k < 4; ++k)
    scene.loads.push_back({centre + 0.01 * Vector3d(k % 2, k / 2, 0.0), Vector3d(0.0, 0.0, -5.0)});
  long step = 0;
  const CutChanges first = adapt_round(controller, cut, scene, step++);
  const TreePointLocator locator(tree);
  const NodeId host = test::active_location(ActiveCut(tree), locator, centre).node;
  EXPECT_NE(std::find(first.refine.begin(), first.refine.end(), host), first.refine.end());
  run_to_steady(controller, cut, scene, step, 20);
  EXPECT_EQ(tree.level(test::active_location(cut, locator, centre).node), 3);
  expect_refinement_near(cut, centre, 0.35);
}

// A stressed body (uniform stress with its tractions) with a small, strongly loaded patch inside
// one coarse tet: the patch's forces, smeared over the coarse corners, are weak against the body's
// stress, so only the finest-level traction reported by the driver refines it — down to the
// finest level, and only where the patch is.
TEST(RefinementController, FinestLoadTractionRefinesAPatchUnderStress) {
  const Vector3d centre(0.61, 0.43, 0.25);
  const double patch_area = M_PI * 0.01 * 0.01;
  for (const bool report_traction : {false, true}) {
    TetTree tree(slab(), 3);
    RefinementController controller(fast_settings());
    ActiveCut cut(tree);
    Scene scene = affine_scene();
    for (int k = 0; k < 4; ++k)
      scene.loads.push_back({centre + 0.005 * Vector3d(k % 2, k / 2, 0.0),
                             Vector3d(0.0, 0.0, -10.0), report_traction ? patch_area / 4 : 0.0});
    long step = 0;
    run_to_steady(controller, cut, scene, step, 10);
    const TreePointLocator locator(tree);
    const int level = tree.level(active_location(cut, locator, centre).node);
    if (!report_traction) {
      EXPECT_EQ(cut.size(), tree.num_roots());  // η ≤ 1 + (smeared patch) < 3 everywhere
      continue;
    }
    EXPECT_EQ(level, 3);
    expect_refinement_near(cut, centre, 0.2);
    EXPECT_LT(cut.size(), tree.num_roots() + 7 * 3 * 4 * 2);  // a path per patch point and level
  }
}

TEST(RefinementController, SteadyStateDoesNotFlicker) {
  TetTree tree(test::slab(), 3);
  RefinementController controller(fast_settings());  // no minimum steps: the worst case
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  for (int r = 0; r < 30; ++r)
    adapt_round(controller, cut, scene, step++);
  int most = 0;
  for (NodeId n = 0; n < tree.pool_size(); ++n)
    most = std::max(most, controller.change_count(n));
  EXPECT_EQ(most, 1);

  // A steady concentrated load at rest: the fringe refined for the load's first, coarse
  // footprint merges once the load sits on finer vertices (two changes), then nothing moves.
  TetTree tree2(test::slab(), 3);
  RefinementController controller2(fast_settings());
  ActiveCut cut2(tree2);
  Scene loaded;
  loaded.loads = top_point_loads();
  const int changing_rounds = run_to_steady(controller2, cut2, loaded, step, 30);
  EXPECT_LT(changing_rounds, 10);
  const std::vector<NodeId> settled = cut2.sorted_nodes();
  for (int r = 0; r < 20; ++r)
    adapt_round(controller2, cut2, loaded, step++);
  EXPECT_EQ(cut2.sorted_nodes(), settled);
  for (NodeId n = 0; n < tree2.pool_size(); ++n)
    EXPECT_LE(controller2.change_count(n), 2) << n;
}

TEST(RefinementController, RefineThenCoarsenWithoutMotionIsTheIdentity) {
  TetTree tree(test::slab(), 2);
  RefinementController controller(fast_settings());
  ActiveCut cut(tree);
  const std::vector<NodeId> before = cut.sorted_nodes();
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  scene.loads = top_point_loads();
  run_to_steady(controller, cut, scene, step, 10);
  ASSERT_GT(cut.size(), tree.num_roots());
  run_to_steady(controller, cut, Scene{}, step, 10);
  EXPECT_EQ(cut.sorted_nodes(), before);
}

}  // namespace
}  // namespace strata
