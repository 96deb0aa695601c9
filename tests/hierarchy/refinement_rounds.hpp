#pragma once
// Shared helpers of the refinement-controller tests: scenes (bump, point loads, affine field with
// its tractions) and decide/apply rounds that check the invariants of every decision.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "refinement_test_utils.hpp"
#include "strata/hierarchy/refinement_controller.hpp"

namespace strata::test {

inline const Vector3d kBumpCentre(0.5, 0.5, 0.25);
inline const Vector3d kGravity(0.0, 0.0, -9.81);

inline DisplacementField steady_bump() {
  return test::bump(kBumpCentre, 0.08, 0.004);
}

// A concentrated downward force on the three top vertices nearest the centre of the top face.
inline std::vector<PointLoad> top_point_loads() {
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
inline CutChanges adapt_round(RefinementController& controller, ActiveCut& cut, const Scene& scene,
                              long step, CutChangeCounts* counts = nullptr) {
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
inline int run_to_steady(RefinementController& controller, ActiveCut& cut, const Scene& scene,
                         long& step, int max_rounds) {
  int changed = 0;
  for (int r = 0; r < max_rounds; ++r) {
    const CutChanges c = adapt_round(controller, cut, scene, step++);
    if (c.refine.empty() && c.coarsen.empty()) return changed;
    ++changed;
  }
  return changed;
}

inline RefinementSettings fast_settings() {
  RefinementSettings s;
  s.min_steps_between_changes = 0;
  return s;
}

inline Scene affine_scene() {
  Scene scene;
  const Matrix3d G = test::affine_gradient();
  scene.u = [G](const Vector3d& X) -> Vector3d { return G * X; };
  scene.tractions = true;
  return scene;
}

// Every refined root lies near the load: its centroid within `radius` of `centre`.
inline void expect_refinement_near(const ActiveCut& cut, const Vector3d& centre, double radius) {
  const TetTree& tree = cut.tree();
  for (const NodeId n : cut.nodes()) {
    if (tree.level(n) == 0) continue;
    const NodeId root = tree.node(n).root;
    EXPECT_LT((node_centroid(tree, root) - centre).norm(), radius) << "refined root " << root;
  }
}

}  // namespace strata::test
