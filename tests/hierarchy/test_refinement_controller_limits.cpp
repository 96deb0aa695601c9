// Refinement controller limits: budget, refinement and coarsening vetoes, the driver's merge
// filter against the budget, minimum steps between changes, reused node ids, level cap, 2:1
// balance, a plugged-in indicator, settings validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "refinement_rounds.hpp"
#include "strata/core/common/error.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/refinement_stress_jump_indicator.hpp"

namespace strata {
namespace {

using namespace strata::test;

TEST(RefinementController, BudgetIsRespectedLargestFirst) {
  TetTree tree(test::slab(), 3);
  RefinementSettings settings = fast_settings();
  settings.max_active_elements = tree.num_roots() + 7 * 5;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  CutSnapshot s = make_snapshot(cut, test::test_material(), scene.u, {}, kGravity, step);
  const CutChanges first = controller.decide(s.state(), cut);
  ASSERT_EQ(first.refine.size(), 5u);
  EXPECT_GT(first.refused, 0);
  // They are the five largest η.
  std::vector<double> eta(first.eta.data(), first.eta.data() + first.eta.size());
  std::sort(eta.begin(), eta.end(), std::greater<>());
  for (const NodeId n : first.refine) {
    const auto t = std::find(s.cut.flat.tet_nodes.begin(), s.cut.flat.tet_nodes.end(), n) -
                   s.cut.flat.tet_nodes.begin();
    EXPECT_GE(first.eta[t], eta[4]);
  }
  for (int r = 0; r < 10; ++r) {
    adapt_round(controller, cut, scene, step++);
    EXPECT_LE(cut.size(), settings.max_active_elements);
  }
  EXPECT_GT(cut.size(), settings.max_active_elements - 7);
}

TEST(RefinementController, MergeFilterChoosesTheMergesBeforeTheElementBudget) {
  // A bump on a uniform level-1 cut: tets under it ask for refinement, siblings far from it
  // merge. With the budget at the cut's size, only the tets the merges free can be refined, so
  // the refinements follow the merges the driver's filter keeps.
  TetTree tree(test::slab(), 3);
  const ActiveCut cut = ActiveCut::uniform(tree, 1);
  const CutSnapshot s = make_snapshot(cut, test::test_material(), steady_bump(), {}, kGravity, 0);
  RefinementSettings settings = fast_settings();
  settings.max_active_elements = cut.size();
  const CutChanges all = RefinementController(settings).decide(s.state(), cut);
  ASSERT_GE(all.coarsen.size(), 3u);
  ASSERT_GE(all.over_threshold, 3);
  for (const std::size_t keep : {std::size_t(0), std::size_t(2)}) {
    RefinementController controller(settings);
    std::size_t offered = 0;
    controller.set_merge_filter([&](const CutState&, const std::vector<NodeId>& parents) {
      offered = parents.size();
      return std::vector<NodeId>(parents.begin(), parents.begin() + keep);
    });
    const CutChanges some = controller.decide(s.state(), cut);
    EXPECT_EQ(offered, all.coarsen.size());
    EXPECT_EQ(some.coarsen.size(), keep);
    EXPECT_EQ(some.refine.size(), keep) << "keep " << keep;
    EXPECT_EQ(some.refused, some.over_threshold - static_cast<Index>(keep));
    EXPECT_LE(cut.size() - 7 * static_cast<Index>(some.coarsen.size()) +
                  7 * static_cast<Index>(some.refine.size()),
              settings.max_active_elements);
  }
}

TEST(RefinementController, VetoIsHonoured) {
  TetTree tree(test::slab(), 2);
  RefinementController controller(fast_settings());
  // Refuse everything left of x = 0.5 (e.g. a fixed region, or an explicit step limit).
  controller.set_refinement_veto(
      [&tree](NodeId n) { return node_centroid(tree, n).x() > kBumpCentre.x(); });
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  Index refused = 0;
  for (int r = 0; r < 5; ++r)
    refused += adapt_round(controller, cut, scene, step++).refused;
  EXPECT_GT(refused, 0);
  EXPECT_GT(cut.size(), tree.num_roots());
  for (const NodeId n : cut.nodes())
    if (tree.level(n) > 0) {
      EXPECT_GT(node_centroid(tree, tree.parent(n)).x(), kBumpCentre.x());
    }
}

TEST(RefinementController, CoarseningVetoPinsNodes) {
  TetTree tree(test::slab(), 2);
  RefinementController controller(fast_settings());
  ActiveCut cut = ActiveCut::uniform(tree, 1);
  // Keep the refinement of every root touching the plane x = 0 (a fixed region, say).
  const auto touches_fixed = [&tree](NodeId n) {
    return tree.tet_positions(n).row(0).minCoeff() < 1e-12;
  };
  controller.set_coarsening_veto([&](NodeId parent) { return !touches_fixed(parent); });
  long step = 0;
  run_to_steady(controller, cut, Scene{}, step, 5);
  Index pinned = 0;
  for (NodeId r = 0; r < tree.num_roots(); ++r) {
    EXPECT_EQ(cut.is_active(r), !touches_fixed(r)) << r;
    pinned += touches_fixed(r);
  }
  EXPECT_GT(pinned, 0);
  EXPECT_EQ(cut.size(), tree.num_roots() + 7 * pinned);
}

TEST(RefinementController, MinimumStepsBetweenChangesOfANode) {
  TetTree tree(test::slab(), 1);
  RefinementSettings settings;
  settings.min_steps_between_changes = 5;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  Scene bumped;
  bumped.u = steady_bump();
  const CutChanges first = adapt_round(controller, cut, bumped, 0);
  ASSERT_FALSE(first.refine.empty());
  for (const NodeId n : first.refine)
    EXPECT_EQ(controller.last_change_step(n), 0);
  // Unloaded from step 1: the refined nodes may merge only from step 5 on.
  for (long step = 1; step < 5; ++step)
    EXPECT_TRUE(adapt_round(controller, cut, Scene{}, step).coarsen.empty()) << step;
  const CutChanges merge = adapt_round(controller, cut, Scene{}, 5);
  EXPECT_EQ(std::set<NodeId>(merge.coarsen.begin(), merge.coarsen.end()),
            std::set<NodeId>(first.refine.begin(), first.refine.end()));
  // Bumped again from step 6: no re-refinement before step 10.
  for (long step = 6; step < 10; ++step) {
    const CutChanges c = adapt_round(controller, cut, bumped, step);
    EXPECT_TRUE(c.refine.empty()) << step;
    EXPECT_GT(c.refused, 0);
  }
  EXPECT_EQ(adapt_round(controller, cut, bumped, 10).refine.size(), first.refine.size());
}

// The driver releases merged subtrees; the tree reuses their ids for the next refinement, and the
// new children must not inherit the old ones' records.
TEST(RefinementController, ReusedNodeIdsStartFresh) {
  TetTree tree(test::slab(), 2);
  RefinementSettings settings;
  settings.min_steps_between_changes = 5;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  CutChanges refine_first;
  refine_first.refine = {7};
  controller.apply(cut, refine_first, 0);
  const NodeId child = tree.child(7, 3);
  CutChanges refine_child;
  refine_child.refine = {child};
  controller.apply(cut, refine_child, 0);
  EXPECT_EQ(controller.last_change_step(child), 0);
  cut.coarsen(child);
  cut.coarsen(7);
  tree.coarsen_subtree(7);  // ids of 7's children go back to the pool
  CutChanges refine_other;
  refine_other.refine = {8};
  controller.apply(cut, refine_other, 1);
  ASSERT_EQ(tree.child(8, 3), child);  // the released block is reused
  EXPECT_EQ(controller.last_change_step(child), RefinementController::kNever);
  EXPECT_EQ(controller.change_count(child), 0);
  EXPECT_EQ(controller.last_change_step(8), 1);
}

TEST(RefinementController, LevelCap) {
  TetTree tree(test::slab(), 3);
  RefinementSettings settings = fast_settings();
  settings.max_level = 1;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  run_to_steady(controller, cut, scene, step, 10);
  EXPECT_EQ(cut.finest_level(), 1);
}

TEST(RefinementController, BalanceKeepsTheCutTwoToOne) {
  TetTree tree(test::slab(), 3);
  RefinementSettings settings = fast_settings();
  settings.balance = true;
  RefinementController controller(settings);
  ActiveCut cut(tree);
  const std::vector<NodeId> before = cut.sorted_nodes();
  long step = 0;
  Scene scene;
  scene.u = test::bump(kBumpCentre, 0.04, 0.002);
  scene.loads = top_point_loads();
  Index balance_refined = 0;
  for (int r = 0; r < 8; ++r) {
    CutChangeCounts counts;
    adapt_round(controller, cut, scene, step++, &counts);
    balance_refined += counts.balance_refined;
    EXPECT_TRUE(is_balanced(cut)) << r;
  }
  EXPECT_EQ(cut.finest_level(), 3);
  EXPECT_GT(balance_refined, 0);
  for (int r = 0; r < 8; ++r) {
    adapt_round(controller, cut, Scene{}, step++);
    EXPECT_TRUE(is_balanced(cut)) << r;
  }
  EXPECT_EQ(cut.sorted_nodes(), before);
}

TEST(RefinementController, StressJumpIndicatorPlugsIn) {
  TetTree tree(test::slab(), 2);
  RefinementSettings settings = fast_settings();
  settings.refine_threshold = 0.5;
  RefinementController controller(settings, std::make_unique<StressJumpIndicator>());
  EXPECT_EQ(controller.indicator().name(), "stress_jump");
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  run_to_steady(controller, cut, scene, step, 10);
  EXPECT_GT(cut.size(), tree.num_roots());
  expect_refinement_near(cut, kBumpCentre, 0.3);
  run_to_steady(controller, cut, affine_scene(), step, 10);
  EXPECT_EQ(cut.size(), tree.num_roots());
}

TEST(RefinementController, SettingsAreValidated) {
  const auto bad = [](auto edit) {
    RefinementSettings s;
    edit(s);
    return s;
  };
  EXPECT_NO_THROW(RefinementController(RefinementSettings{}));
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.refine_threshold = 0.0; })), InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.coarsen_indicator_fraction = 1.5; })),
               InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.coarsen_tolerance = -1.0; })), InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.stress_floor = 0.0; })), InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.min_steps_between_changes = -1; })),
               InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.max_active_elements = -5; })), InputError);
  EXPECT_THROW(RefinementController(bad([](auto& s) { s.max_level = -2; })), InputError);
}

}  // namespace
}  // namespace strata
