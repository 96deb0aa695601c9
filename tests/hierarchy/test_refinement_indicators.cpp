// Refinement indicators: the force indicator's bound for uniform stress, its scale invariance, its
// response to loads inside a coarse tet and to local bumps; the stress-jump alternative.
#include <gtest/gtest.h>

#include <cmath>

#include "refinement_test_utils.hpp"
#include "strata/hierarchy/refinement_force_indicator.hpp"
#include "strata/hierarchy/refinement_stress_jump_indicator.hpp"

namespace strata {
namespace {

using test::affine_gradient;
using test::bump;
using test::kSlabMax;
using test::make_snapshot;
using test::mixed_cut;
using test::node_centroid;
using test::PointLoad;
using test::set_surface_tractions;
using test::slab;
using test::test_material;

TEST(ForceIndicator, UniformStressWithItsTractionsStaysAtOrBelowOne) {
  TetTree tree(slab(), 2);
  const Matrix3d G = affine_gradient();
  const auto affine = [&](const Vector3d& X) -> Vector3d {
    return G * X + Vector3d(0.1, -0.2, 0.3);
  };
  const ForceIndicator indicator;
  std::vector<ActiveCut> cuts;
  cuts.emplace_back(tree);
  cuts.push_back(ActiveCut::uniform(tree, 1));
  cuts.push_back(mixed_cut(tree));
  for (const ActiveCut& cut : cuts) {
    test::CutSnapshot s = make_snapshot(cut, test_material(), affine, {});
    set_surface_tractions(s, Vector3d::Zero());
    VectorXd eta;
    indicator.evaluate(s.state(), eta);
    // The stress part is exactly 1 (all tets carry the same stress), the loads' part ≤ 1.
    EXPECT_NEAR(eta.minCoeff(), 1.0, 1e-6) << cut.size();
    EXPECT_LE(eta.maxCoeff(), 1.0 + 1e-9) << cut.size();
    // The tractions are really there: they set the load scale to a fair fraction of the stress.
    const ForceReference ref = indicator.reference(s.state());
    EXPECT_GT(ref.load_rms, 0.2 * ref.stress_rms);
    EXPECT_EQ(ref.scale, ref.stress_rms);

    // Gravity is proportional to mass: adding it changes nothing.
    test::CutSnapshot heavy = make_snapshot(cut, test_material(), affine, {});
    set_surface_tractions(heavy, Vector3d(0.0, 0.0, -9.81));
    VectorXd eta_heavy;
    indicator.evaluate(heavy.state(), eta_heavy);
    EXPECT_LE((eta_heavy - eta).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(ForceIndicator, RigidMotionAndGravityAloneGiveZero) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = mixed_cut(tree);
  const Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const auto rigid = [&](const Vector3d& X) -> Vector3d {
    return R * X - X + Vector3d(1.0, 2.0, 3.0);
  };
  const test::CutSnapshot s =
      make_snapshot(cut, test_material(), rigid, {}, Vector3d(0.0, 0.0, -9.81));
  VectorXd eta;
  ForceIndicator().evaluate(s.state(), eta);
  EXPECT_LE(eta.maxCoeff(), 1e-6);
}

TEST(ForceIndicator, ScaleFreeInLengthStiffnessAndLoad) {
  // Scene A: 1 m slab, E = 1e6. Scene B: 10 cm slab, E = 1e8, same strains: stresses ×100,
  // forces × E·L² = ×1. η must agree.
  const std::vector<double> scales{1.0, 0.1};
  const std::vector<double> moduli{1e6, 1e8};
  std::vector<VectorXd> force_eta(2), jump_eta(2);
  for (int i = 0; i < 2; ++i) {
    const double s = scales[i];
    TetTree tree(slab(s), 2);
    const ActiveCut cut = mixed_cut(tree);
    const test::DisplacementField u = bump(s * Vector3d(0.3, 0.6, 0.25), s * 0.2, s * 0.01);
    const std::vector<PointLoad> loads{{s * Vector3d(0.71, 0.33, 0.25), Vector3d(1.0, -2.0, -30.0)},
                                       {s * Vector3d(0.2, 0.9, 0.0), Vector3d(0.0, 0.0, 5.0)}};
    const test::CutSnapshot snap =
        make_snapshot(cut, test_material(moduli[i]), u, loads, Vector3d(0.0, 0.0, -9.81));
    ForceIndicator().evaluate(snap.state(), force_eta[i]);
    StressJumpIndicator().evaluate(snap.state(), jump_eta[i]);
  }
  EXPECT_GT(force_eta[0].maxCoeff(), 3.0);  // not trivially zero
  EXPECT_LE((force_eta[0] - force_eta[1]).cwiseAbs().maxCoeff(), 1e-8 * force_eta[0].maxCoeff());
  EXPECT_GT(jump_eta[0].maxCoeff(), 0.1);
  EXPECT_LE((jump_eta[0] - jump_eta[1]).cwiseAbs().maxCoeff(), 1e-8 * jump_eta[0].maxCoeff());
}

// One indicator evaluated on different trees (its cached surface area must follow the tree).
TEST(ForceIndicator, SurfaceAreaCacheFollowsTheTree) {
  const ForceIndicator shared;
  const std::vector<PointLoad> loads{{Vector3d(0.5, 0.5, 0.25), Vector3d(0, 0, -1.0)}};
  for (const double scale : {1.0, 0.5, 1.0}) {
    TetTree tree(slab(scale), 1);
    const ActiveCut cut(tree);
    std::vector<PointLoad> scaled = loads;
    scaled[0].point *= scale;
    const test::CutSnapshot s = make_snapshot(cut, test_material(), test::no_motion, scaled);
    // Surface of the box: 2 (1·1 + 1·0.25 + 1·0.25) = 3 m² times scale².
    EXPECT_NEAR(ForceIndicator::body_surface_area(tree), 3.0 * scale * scale, 1e-12);
    EXPECT_DOUBLE_EQ(shared.reference(s.state()).load_rms,
                     ForceIndicator().reference(s.state()).load_rms);
  }
}

// A small loaded patch inside the top face of one coarse tet: no coarse vertex in it, but the
// load reaches that tet's corners and the indicator fires there, at rest (no stress yet).
TEST(ForceIndicator, PatchInsideACoarseTetIsSeenAtRest) {
  TetTree tree(slab(), 2);
  const ActiveCut roots(tree);
  // A root with a face on the top surface, and a point inside that face.
  NodeId host = kNoNode;
  Vector3d centre = Vector3d::Zero();
  for (NodeId r = 0; r < tree.num_roots() && host == kNoNode; ++r) {
    const Matrix3x4d x = tree.tet_positions(r);
    Vector3d face = Vector3d::Zero();
    int top = 0;
    for (int i = 0; i < 4; ++i)
      if (std::abs(x(2, i) - kSlabMax.z()) < 1e-12) {
        face += x.col(i) / 3.0;
        ++top;
      }
    if (top == 3 && (face - Vector3d(0.5, 0.5, 0.25)).norm() < 0.2) {
      host = r;
      centre = face;
    }
  }
  ASSERT_NE(host, kNoNode);
  std::vector<PointLoad> patch;
  for (int k = 0; k < 6; ++k) {
    const double a = 2.0 * M_PI * k / 6.0;
    patch.push_back({centre + 0.01 * Vector3d(std::cos(a), std::sin(a), 0.0), Vector3d(0, 0, -10)});
  }
  const test::CutSnapshot s =
      make_snapshot(roots, test_material(), test::no_motion, patch, Vector3d(0.0, 0.0, -9.81));
  VectorXd eta;
  const ForceIndicator indicator;
  indicator.evaluate(s.state(), eta);
  const ForceReference ref = indicator.reference(s.state());
  EXPECT_LT(ref.stress_rms, 1e-9 * ref.load_rms);  // rounding of σ(F = I) only
  EXPECT_EQ(ref.scale, ref.load_rms);
  const std::vector<NodeId>& nodes = s.cut.flat.tet_nodes;
  for (std::size_t t = 0; t < nodes.size(); ++t) {
    const double distance = (node_centroid(tree, nodes[t]) - centre).norm();
    if (nodes[t] == host) {
      EXPECT_GT(eta[t], 3.0);
    }
    // Far from the patch the only load left is −m_v·F/M (the patch's share of the mean
    // acceleration removed with gravity): small against the threshold 3.
    if (distance > 0.45) {
      EXPECT_LT(eta[t], 0.2) << distance;
    }
  }
}

TEST(ForceIndicator, BumpPeaksAtTheBump) {
  TetTree tree(slab(), 1);
  const ActiveCut cut = ActiveCut::uniform(tree, 1);
  const Vector3d centre(0.3, 0.6, 0.25);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), bump(centre, 0.1, 0.005), {});
  for (const bool jump : {false, true}) {
    VectorXd eta;
    if (jump)
      StressJumpIndicator().evaluate(s.state(), eta);
    else
      ForceIndicator().evaluate(s.state(), eta);
    Index peak = 0;
    eta.maxCoeff(&peak);
    EXPECT_LT((node_centroid(tree, s.cut.flat.tet_nodes[peak]) - centre).norm(), 0.15);
    for (Index t = 0; t < eta.size(); ++t)
      if ((node_centroid(tree, s.cut.flat.tet_nodes[t]) - centre).norm() > 0.5) {
        EXPECT_LT(eta[t], 0.05 * eta[peak]) << (jump ? "jump" : "force");
      }
  }
}

TEST(StressJumpIndicator, UniformStressHasNoJumpOnAnyCut) {
  TetTree tree(slab(), 2);
  const Matrix3d G = affine_gradient();
  const auto affine = [&](const Vector3d& X) -> Vector3d { return G * X; };
  const ActiveCut cut = mixed_cut(tree);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), affine, {});
  VectorXd eta;
  StressJumpIndicator().evaluate(s.state(), eta);
  EXPECT_LE(eta.maxCoeff(), 1e-9);
}

// Face neighbours on a mixed cut, checked against brute-force point location over all tets.
TEST(StressJumpIndicator, FaceNeighboursOnAMixedCut) {
  TetTree tree(slab(), 2);
  const ActiveCut cut = mixed_cut(tree);
  const test::CutSnapshot s = make_snapshot(cut, test_material(), test::no_motion, {});
  const MatrixX4i nb = StressJumpIndicator::face_neighbours(s.state());
  const TetMesh& mesh = s.cut.flat.mesh;
  Index interface_faces = 0;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    Vector3d centre = Vector3d::Zero();
    for (int i = 0; i < 4; ++i)
      centre += 0.25 * mesh.vertices.row(mesh.tets(t, i)).transpose();
    for (int k = 0; k < 4; ++k) {
      Vector3d face = Vector3d::Zero();
      for (int i = 0; i < 4; ++i)
        if (i != k) face += mesh.vertices.row(mesh.tets(t, i)).transpose() / 3.0;
      const Vector3d outside = face + 1e-6 * (face - centre);
      Index expected = -1;
      for (Index o = 0; o < mesh.tets.rows(); ++o) {
        const auto v = [&](int i) -> Vector3d { return mesh.vertices.row(mesh.tets(o, i)); };
        if (tet_barycentric_coordinates(outside, v(0), v(1), v(2), v(3)).minCoeff() >= -1e-12)
          expected = o;
      }
      EXPECT_EQ(nb(t, k), expected) << t << " " << k;
      int shared = 0;
      if (expected >= 0)
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j)
            shared += mesh.tets(t, i) == mesh.tets(expected, j);
      interface_faces += expected >= 0 && shared < 3;
    }
  }
  EXPECT_GT(interface_faces, 20);  // the cut really has non-conforming faces
}

}  // namespace
}  // namespace strata
