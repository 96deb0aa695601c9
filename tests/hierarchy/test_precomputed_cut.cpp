// Precomputed cuts: node paths, the recorder's windows, validation, playback against the uniform
// mode and across a schedule, and the conforming mesh of a cut (checked face by face).
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "adaptive_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/hierarchy/conforming_mesh.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/precomputed_cut.hpp"

namespace strata {
namespace {

using testing::box_load;
using testing::fixed_plane;
using testing::hierarchy;
using testing::rubber;

TetMesh test_box() {
  return box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.5, 1.0), {2, 2, 2});
}

/// Refines random active nodes (probability p per node and round) for `rounds` rounds.
void refine_randomly(ActiveCut& cut, double p, int rounds, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int round = 0; round < rounds; ++round) {
    const std::vector<NodeId> nodes = cut.sorted_nodes();
    for (NodeId n : nodes)
      if (cut.tree().can_refine(n) && u(rng) < p) cut.refine(n);
  }
}

std::set<std::string> path_set(const std::vector<NodePath>& paths) {
  std::set<std::string> set;
  for (const NodePath& path : paths)
    set.insert(to_string(path));
  return set;
}

TEST(PrecomputedCut, NodePathsRoundTrip) {
  TetMesh coarse = test_box();
  TetTree tree(coarse, 3);
  ActiveCut cut(tree);
  std::mt19937 rng(3);
  refine_randomly(cut, 0.4, 3, rng);
  for (NodeId n : cut.nodes()) {
    const NodePath path = node_path(tree, n);
    EXPECT_EQ(path.level(), tree.level(n));
    EXPECT_EQ(path.root, tree.node(n).root);
    EXPECT_EQ(parse_node_path(to_string(path), "x"), path);
    EXPECT_EQ(key_path(node_key(path)), path);
    EXPECT_EQ(node_key(tree, n), node_key(path));
  }
  EXPECT_EQ(to_string(NodePath{12, {3, 0, 5}}), "12.305");
  EXPECT_EQ(parse_node_path("7", "x"), (NodePath{7, {}}));
  for (const char* bad : {"", "a", "1.", "1.8", "-1", "1.2x", ".3"})
    EXPECT_THROW(parse_node_path(bad, "x"), InputError) << bad;
}

TEST(PrecomputedCut, WindowsHoldTheNodesRefinedInThem) {
  TetMesh coarse = test_box();
  TetTree tree(coarse, 2);
  ActiveCut cut(tree);
  CutRecorder recorder;
  cut.refine(0);  // t = 0 … 0.4: root 0 refined
  recorder.record(cut, 0.0);
  recorder.record(cut, 0.4);
  cut.coarsen(0);
  const NodeId first = cut.refine(5);  // t = 0.6 … 1: root 5 and its child 3
  cut.refine(first + 3);
  recorder.record(cut, 0.6);
  recorder.record(cut, 1.0);
  const PrecomputedCut one = recorder.schedule(1, coarse, 2, 0.01);
  ASSERT_EQ(one.windows.size(), 1u);
  EXPECT_EQ(path_set(one.windows[0].refined), (std::set<std::string>{"0", "5", "5.3"}));
  const PrecomputedCut two = recorder.schedule(2, coarse, 2, 0.01);
  ASSERT_EQ(two.windows.size(), 2u);
  EXPECT_EQ(path_set(two.windows[0].refined), (std::set<std::string>{"0"}));
  EXPECT_EQ(path_set(two.windows[1].refined), (std::set<std::string>{"5", "5.3"}));
  EXPECT_DOUBLE_EQ(two.windows[1].start, 0.5);
  EXPECT_EQ(two.window_at(0.2), 0u);
  EXPECT_EQ(two.window_at(0.5), 1u);
  EXPECT_EQ(two.window_at(7.0), 1u);  // the last window extends beyond the recorded runs
  EXPECT_EQ(one.finest_level(), 2);
  EXPECT_NO_THROW(validate_precomputed_cut(two, coarse, 2, "cut"));
  // Played back on a fresh tree: the union cut.
  TetTree fresh(coarse, 2);
  const std::vector<NodeId> nodes = cut_nodes(fresh, one.windows[0].refined);
  EXPECT_EQ(static_cast<Index>(nodes.size()), coarse.tets.rows() - 2 + 8 + 7 + 8);
  EXPECT_NO_THROW(ActiveCut(fresh, nodes));
}

TEST(PrecomputedCut, TheStaticCutIsAtLeastAsFineAsEveryRecordedCut) {
  TetMesh coarse = test_box();
  TetTree tree(coarse, 3);
  ActiveCut cut(tree);
  CutRecorder recorder;
  std::mt19937 rng(11);
  std::vector<std::vector<NodePath>> recorded;
  for (int t = 0; t < 6; ++t) {
    // Change the cut: coarsen some parents, refine some nodes.
    for (NodeId n : cut.sorted_nodes()) {
      const NodeId p = tree.parent(n);
      if (p != kNoNode && cut.is_active(n) && cut.can_coarsen(p) && rng() % 3 == 0) cut.coarsen(p);
    }
    refine_randomly(cut, 0.2, 1, rng);
    recorder.record(cut, t);
    std::vector<NodePath> paths;
    for (NodeId n : cut.nodes())
      paths.push_back(node_path(tree, n));
    recorded.push_back(paths);
  }
  const PrecomputedCut schedule = recorder.schedule(1, coarse, 3, 0.01);
  const std::set<std::string> refined = path_set(schedule.windows[0].refined);
  for (const std::vector<NodePath>& paths : recorded) {
    for (NodePath path : paths) {
      // Every strict ancestor of a recorded active node is refined.
      while (!path.slots.empty()) {
        path.slots.pop_back();
        EXPECT_TRUE(refined.count(to_string(path))) << to_string(path);
      }
    }
  }
  EXPECT_NO_THROW(validate_precomputed_cut(schedule, coarse, 3, "cut"));
}

TEST(PrecomputedCut, ValidationNamesTheProblem) {
  TetMesh coarse = test_box();
  TetTree tree(coarse, 2);
  ActiveCut cut(tree);
  cut.refine(cut.refine(4));
  CutRecorder recorder;
  recorder.record(cut, 1.0);
  const PrecomputedCut good = recorder.schedule(1, coarse, 2, 0.01);
  const auto message = [&](const PrecomputedCut& bad, int levels = 2) {
    try {
      validate_precomputed_cut(bad, coarse, levels, "cut.json");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  PrecomputedCut other = good;
  other.coarse_tets += 1;
  EXPECT_NE(message(other).find("made for a coarse mesh of"), std::string::npos);
  other = good;
  other.coarse_centroid.x() += 0.1;
  EXPECT_NE(message(other).find("centroid"), std::string::npos);
  other = good;
  other.windows[0].refined.push_back({999, {}});
  EXPECT_NE(message(other).find("root 999"), std::string::npos);
  EXPECT_NE(message(good, 1).find("deeper than hierarchy.levels"), std::string::npos);
  other = good;
  other.windows[0].refined.push_back({3, {1}});
  EXPECT_NE(message(other).find("without its parent \"3\""), std::string::npos);
  other = good;
  other.windows.push_back({0.5, 2.0, {}});
  EXPECT_NE(message(other).find("windows.1.start"), std::string::npos);
  EXPECT_EQ(message(good), "no error");
}

/// Conformity checked face by face: every face of the mesh is shared by two tets or lies on the
/// boundary, and the boundary has the coarse mesh's area; no vertex of the mesh lies inside an
/// edge of a tet; the volume is the coarse one.
void expect_conforming(const TetMesh& mesh, const TetMesh& coarse, const std::string& label) {
  ASSERT_NO_THROW(validate_tet_mesh(mesh, label));
  const auto area = [](const MatrixX3d& v, int a, int b, int c) {
    return 0.5 * (v.row(b) - v.row(a)).cross(v.row(c) - v.row(a)).norm();
  };
  double volume = 0.0;
  std::map<std::array<int, 3>, int> faces;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const Vector3d a = mesh.vertices.row(mesh.tets(t, 0)).transpose();
    const double v = (mesh.vertices.row(mesh.tets(t, 1)).transpose() - a)
                         .cross(mesh.vertices.row(mesh.tets(t, 2)).transpose() - a)
                         .dot(mesh.vertices.row(mesh.tets(t, 3)).transpose() - a) /
                     6.0;
    EXPECT_GT(v, 0.0) << label << " tet " << t;
    volume += v;
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> f{};
      int o = 0;
      for (int j = 0; j < 4; ++j)
        if (j != k) f[o++] = mesh.tets(t, j);
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  double boundary_area = 0.0;
  for (const auto& [f, count] : faces) {
    EXPECT_LE(count, 2) << label;
    if (count == 1) boundary_area += area(mesh.vertices, f[0], f[1], f[2]);
  }
  double coarse_area = 0.0, coarse_volume = 0.0;
  const MatrixX3i boundary = boundary_faces(coarse.tets);
  for (Index f = 0; f < boundary.rows(); ++f)
    coarse_area += area(coarse.vertices, boundary(f, 0), boundary(f, 1), boundary(f, 2));
  for (Index t = 0; t < coarse.tets.rows(); ++t) {
    const Vector3d a = coarse.vertices.row(coarse.tets(t, 0)).transpose();
    coarse_volume += std::abs((coarse.vertices.row(coarse.tets(t, 1)).transpose() - a)
                                  .cross(coarse.vertices.row(coarse.tets(t, 2)).transpose() - a)
                                  .dot(coarse.vertices.row(coarse.tets(t, 3)).transpose() - a)) /
                     6.0;
  }
  EXPECT_NEAR(volume, coarse_volume, 1e-12 * coarse_volume) << label;
  // A hanging vertex leaves two unmatched faces on each side of it: extra boundary area.
  EXPECT_NEAR(boundary_area, coarse_area, 1e-12 * coarse_area) << label;
  // No vertex strictly inside a tet edge (the midpoint of every edge is not a vertex).
  std::map<std::array<long long, 3>, int> vertex_at;
  const auto key = [](const Vector3d& p) {
    return std::array<long long, 3>{std::llround(p.x() * 1e9), std::llround(p.y() * 1e9),
                                    std::llround(p.z() * 1e9)};
  };
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    vertex_at[key(mesh.vertices.row(v).transpose())] = static_cast<int>(v);
  Index hanging = 0;
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const Vector3d m =
            0.5 *
            (mesh.vertices.row(mesh.tets(t, i)) + mesh.vertices.row(mesh.tets(t, j))).transpose();
        if (vertex_at.count(key(m))) ++hanging;
      }
  EXPECT_EQ(hanging, 0) << label;
}

TEST(ConformingMesh, UniformCutsNeedNoClosure) {
  const TetMesh coarse = test_box();
  TetTree tree(coarse, 2);
  ActiveCut cut = ActiveCut::uniform(tree, 2);
  const ConformingMesh mesh = conforming_cut_mesh(cut);
  EXPECT_EQ(mesh.closure_refinements, 0);
  EXPECT_EQ(mesh.centres, 0);
  EXPECT_EQ(mesh.mesh.tets.rows(), coarse.tets.rows() * 64);
  EXPECT_EQ(mesh.green.maxCoeff(), 0);
  expect_conforming(mesh.mesh, coarse, "uniform");
}

TEST(ConformingMesh, RandomCutsBecomeConforming) {
  const TetMesh coarse = test_box();
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    TetTree tree(coarse, 3);
    ActiveCut cut(tree);
    std::mt19937 rng(seed);
    refine_randomly(cut, 0.3, 3, rng);
    const Index before = cut.size();
    const ConformingMesh mesh = conforming_cut_mesh(cut);
    EXPECT_GT(mesh.green.maxCoeff(), 0) << seed;  // the random cuts have hanging vertices
    EXPECT_GE(mesh.mesh.tets.rows(), before);
    expect_conforming(mesh.mesh, coarse, "seed " + std::to_string(seed));
  }
}

TEST(ConformingMesh, ABalancedCutNeedsNoRedClosure) {
  // 2:1 balanced: no vertex two levels finer on an edge of a face neighbour. Edge neighbours can
  // still differ by two levels, so the closure may refine a few; it stays far below uniform.
  const TetMesh coarse = test_box();
  TetTree tree(coarse, 3);
  ActiveCut cut(tree);
  std::mt19937 rng(5);
  refine_randomly(cut, 0.15, 3, rng);
  balance_cut(cut);
  const Index before = cut.size();
  const ConformingMesh mesh = conforming_cut_mesh(cut);
  EXPECT_LT(mesh.closure_refinements, before / 10);
  EXPECT_LT(mesh.mesh.tets.rows(), 3 * before);
  expect_conforming(mesh.mesh, coarse, "balanced");
}

// --- playback --------------------------------------------------------------------------------

struct Bar {
  TetMesh coarse = box_tet_mesh(Vector3d::Zero(), Vector3d(1, 0.25, 0.25), {4, 1, 1});
  std::vector<DirichletSpec> fixed = {fixed_plane("fixed.0", Vector3d::Zero(), Vector3d::UnitX())};
  std::vector<RegionLoad> loads = {
      box_load(Vector3d(1, -1, -1), Vector3d(1, 1, 1), Vector3d(0, 0, -200.0))};
};

SolverSettings implicit_settings(double duration) {
  SolverSettings settings;
  settings.mode = SimulationMode::dynamic;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 0.005;
  settings.duration = duration;
  return settings;
}

std::shared_ptr<const PrecomputedCut> uniform_cut(const TetMesh& coarse, int levels, int level) {
  TetTree tree(coarse, levels);
  ActiveCut cut = ActiveCut::uniform(tree, level);
  CutRecorder recorder;
  recorder.record(cut, 0.0);
  return std::make_shared<const PrecomputedCut>(recorder.schedule(1, coarse, levels, 0.01, 1.0));
}

TEST(PrecomputedPlayback, AUniformCutMatchesTheUniformMode) {
  const Bar bar;
  HierarchySettings precomputed = hierarchy(2, HierarchyMode::precomputed);
  precomputed.precomputed = uniform_cut(bar.coarse, 2, 1);
  AdaptiveSimulation played(bar.coarse, precomputed,
                            {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads},
                            implicit_settings(0.05));
  AdaptiveSimulation uniform(bar.coarse, hierarchy(2, HierarchyMode::uniform, 1),
                             {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads},
                             implicit_settings(0.05));
  while (!uniform.finished()) {
    played.advance();
    uniform.advance();
  }
  ASSERT_EQ(played.cut().size(), uniform.cut().size());
  const MatrixX3d probe = (MatrixX3d(1, 3) << 1.0, 0.125, 0.125).finished();
  const MatrixX3d u_played = played.displacements(played.locate(probe, "p", 1e-9));
  const MatrixX3d u_uniform = uniform.displacements(uniform.locate(probe, "p", 1e-9));
  EXPECT_GT(u_uniform.norm(), 1e-4);
  EXPECT_LT((u_played - u_uniform).norm(), 1e-12 * u_uniform.norm());
  EXPECT_TRUE(played.changes().empty());
}

TEST(PrecomputedPlayback, ASchedulesSwitchesAtItsWindowsAndKeepsTheEnergy) {
  // Coarse for t < 0.025, level 1 from then on: one refinement at the window start, which keeps
  // kinetic + elastic energy (the new vertices lie on the old linear field).
  const Bar bar;
  TetTree tree(bar.coarse, 2);
  CutRecorder recorder;
  ActiveCut coarse_cut(tree);
  recorder.record(coarse_cut, 0.0);
  ActiveCut fine_cut = ActiveCut::uniform(tree, 1);
  recorder.record(fine_cut, 0.05);
  auto schedule = std::make_shared<PrecomputedCut>(recorder.schedule(2, bar.coarse, 2, 0.01));
  ASSERT_TRUE(schedule->windows[0].refined.empty());
  HierarchySettings settings = hierarchy(2, HierarchyMode::precomputed);
  settings.precomputed = schedule;
  AdaptiveSimulation run(bar.coarse, settings,
                         {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads},
                         implicit_settings(0.05));
  while (!run.finished())
    run.advance();
  ASSERT_EQ(run.changes().size(), 1u);
  const CutChangeRecord& change = run.changes()[0];
  EXPECT_EQ(change.step, 5);  // t = 0.025 = 5 dt
  EXPECT_EQ(change.tets_before, bar.coarse.tets.rows());
  EXPECT_EQ(change.tets_after, 8 * bar.coarse.tets.rows());
  EXPECT_GT(change.energy_before, 0.0);
  EXPECT_NEAR(change.energy_after, change.energy_before, 1e-9 * change.energy_before);
  EXPECT_EQ(run.precomputed_window(), 1u);
}

TEST(PrecomputedPlayback, RejectsACutOfAnotherMesh) {
  const Bar bar;
  HierarchySettings settings = hierarchy(2, HierarchyMode::precomputed);
  settings.precomputed = uniform_cut(test_box(), 2, 1);
  EXPECT_THROW(
      AdaptiveSimulation(bar.coarse, settings,
                         {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads},
                         implicit_settings(0.05)),
      InputError);
  settings.precomputed = nullptr;
  EXPECT_THROW(
      AdaptiveSimulation(bar.coarse, settings,
                         {.material = rubber(), .dirichlet = bar.fixed, .loads = bar.loads},
                         implicit_settings(0.05)),
      InputError);
}

}  // namespace
}  // namespace strata
