// Refinement controller: decide/apply rounds with fields recomputed on every cut, as the adaptive
// driver runs them. Uniform stress, localised loads and bumps, load removal, flicker, identity,
// budget, veto, minimum steps, level cap and 2:1 balance.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "refinement_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/refinement_controller.hpp"
#include "strata/hierarchy/refinement_stress_jump_indicator.hpp"

namespace strata {
namespace {

using test::CutSnapshot;
using test::DisplacementField;
using test::make_snapshot;
using test::node_centroid;
using test::PointLoad;

const Vector3d kBumpCentre(0.5, 0.5, 0.25);
const Vector3d kGravity(0.0, 0.0, -9.81);

DisplacementField steady_bump() {
  return test::bump(kBumpCentre, 0.08, 0.004);
}

// A concentrated downward force on the three top vertices nearest the centre of the top face.
std::vector<PointLoad> top_point_loads() {
  return {{Vector3d(0.5, 0.5, 0.25), Vector3d(0, 0, -20.0)},
          {Vector3d(0.5 + 1.0 / 6.0, 0.5, 0.25), Vector3d(0, 0, -20.0)},
          {Vector3d(0.5, 0.5 + 1.0 / 6.0, 0.25), Vector3d(0, 0, -20.0)}};
}

// The scene of one round: a displacement field, finest-level loads and whether surface
// tractions in equilibrium with the (affine) stress are added.
struct Scene {
  DisplacementField u = test::no_motion;
  std::vector<PointLoad> loads;
  bool tractions = false;
};

// One decide/apply round at `step`; checks the invariants of a decision.
CutChanges round(RefinementController& controller, ActiveCut& cut, const Scene& scene, long step,
                 CutChangeCounts* counts = nullptr) {
  CutSnapshot s = make_snapshot(cut, test::test_material(), scene.u, scene.loads, kGravity, step);
  if (scene.tractions) test::set_surface_tractions(s, kGravity);
  CutChanges changes = controller.decide(s.state(), cut);
  const std::set<NodeId> coarsen(changes.coarsen.begin(), changes.coarsen.end());
  for (const NodeId n : changes.refine) {
    EXPECT_TRUE(cut.is_active(n));
    EXPECT_FALSE(coarsen.count(n));
    EXPECT_FALSE(coarsen.count(cut.tree().parent(n))) << "refined and coarsened together";
  }
  for (const NodeId p : changes.coarsen)
    EXPECT_TRUE(cut.can_coarsen(p));
  const CutChangeCounts c = controller.apply(cut, changes, step);
  if (counts) *counts = c;
  EXPECT_NO_THROW(cut.validate());
  return changes;
}

// Rounds until nothing changes (at most `max_rounds`); returns the number of rounds that changed.
int run_to_steady(RefinementController& controller, ActiveCut& cut, const Scene& scene, long& step,
                  int max_rounds) {
  int changed = 0;
  for (int r = 0; r < max_rounds; ++r) {
    const CutChanges c = round(controller, cut, scene, step++);
    if (c.refine.empty() && c.coarsen.empty()) return changed;
    ++changed;
  }
  return changed;
}

RefinementSettings fast_settings() {
  RefinementSettings s;
  s.min_steps_between_changes = 0;
  return s;
}

Scene affine_scene() {
  Scene scene;
  const Matrix3d G = test::affine_gradient();
  scene.u = [G](const Vector3d& X) -> Vector3d { return G * X; };
  scene.tractions = true;
  return scene;
}

TEST(RefinementController, UniformStressNeverRefines) {
  TetTree tree(test::slab(), 2);
  for (const double threshold : {3.0, 1.05}) {
    RefinementSettings settings = fast_settings();
    settings.refine_threshold = threshold;
    RefinementController controller(settings);
    ActiveCut cut(tree);
    long step = 0;
    for (int r = 0; r < 5; ++r) {
      const CutChanges c = round(controller, cut, affine_scene(), step++);
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
    round(controller, cut, affine_scene(), step++);
  EXPECT_EQ(cut.sorted_nodes(), roots.sorted_nodes());
}

// Every refined root lies near the load: its centroid within `radius` of `centre`.
void expect_refinement_near(const ActiveCut& cut, const Vector3d& centre, double radius) {
  const TetTree& tree = cut.tree();
  for (const NodeId n : cut.nodes()) {
    if (tree.level(n) == 0) continue;
    const NodeId root = tree.node(n).root;
    EXPECT_LT((node_centroid(tree, root) - centre).norm(), radius) << "refined root " << root;
  }
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
    round(controller, cut, unloaded, step++);
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
  const CutChanges first = round(controller, cut, scene, step++);
  const TreePointLocator locator(tree);
  const NodeId host = test::active_location(ActiveCut(tree), locator, centre).node;
  EXPECT_NE(std::find(first.refine.begin(), first.refine.end(), host), first.refine.end());
  run_to_steady(controller, cut, scene, step, 20);
  EXPECT_EQ(tree.level(test::active_location(cut, locator, centre).node), 3);
  expect_refinement_near(cut, centre, 0.35);
}

TEST(RefinementController, SteadyStateDoesNotFlicker) {
  TetTree tree(test::slab(), 3);
  RefinementController controller(fast_settings());  // no minimum steps: the worst case
  ActiveCut cut(tree);
  long step = 0;
  Scene scene;
  scene.u = steady_bump();
  for (int r = 0; r < 30; ++r)
    round(controller, cut, scene, step++);
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
    round(controller2, cut2, loaded, step++);
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
    round(controller, cut, scene, step++);
    EXPECT_LE(cut.size(), settings.max_active_elements);
  }
  EXPECT_GT(cut.size(), settings.max_active_elements - 7);
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
    refused += round(controller, cut, scene, step++).refused;
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
  const CutChanges first = round(controller, cut, bumped, 0);
  ASSERT_FALSE(first.refine.empty());
  for (const NodeId n : first.refine)
    EXPECT_EQ(controller.last_change_step(n), 0);
  // Unloaded from step 1: the refined nodes may merge only from step 5 on.
  for (long step = 1; step < 5; ++step)
    EXPECT_TRUE(round(controller, cut, Scene{}, step).coarsen.empty()) << step;
  const CutChanges merge = round(controller, cut, Scene{}, 5);
  EXPECT_EQ(std::set<NodeId>(merge.coarsen.begin(), merge.coarsen.end()),
            std::set<NodeId>(first.refine.begin(), first.refine.end()));
  // Bumped again from step 6: no re-refinement before step 10.
  for (long step = 6; step < 10; ++step) {
    const CutChanges c = round(controller, cut, bumped, step);
    EXPECT_TRUE(c.refine.empty()) << step;
    EXPECT_GT(c.refused, 0);
  }
  EXPECT_EQ(round(controller, cut, bumped, 10).refine.size(), first.refine.size());
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
    round(controller, cut, scene, step++, &counts);
    balance_refined += counts.balance_refined;
    EXPECT_TRUE(is_balanced(cut)) << r;
  }
  EXPECT_EQ(cut.finest_level(), 3);
  EXPECT_GT(balance_refined, 0);
  for (int r = 0; r < 8; ++r) {
    round(controller, cut, Scene{}, step++);
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
