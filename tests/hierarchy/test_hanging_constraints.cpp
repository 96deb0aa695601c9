// Hanging-vertex constraints x = C q on mixed-level cuts: detection against brute-force point
// location, structure of C, geometric conformity, patch and rigid-motion tests with StVK, energy
// consistency of the reduced forces, and mass conservation across cuts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/fem/tet_rest_data.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_balance.hpp"
#include "strata/hierarchy/hanging_constraints.hpp"
#include "strata/hierarchy/uniform_refinement.hpp"

namespace strata {
namespace {

const Vector3d kBoxMin = Vector3d::Zero();
const Vector3d kBoxMax(2.0, 1.5, 1.0);

TetMesh test_box() {
  return box_tet_mesh(kBoxMin, kBoxMax, {2, 2, 2});
}

// Root 0 refined to level 1 and two of its children to level 2; root 21 refined to level 2 in
// full. Level-2 tets touch level-0 tets: chains of hanging vertices, vertices a quarter along
// coarse edges and inside coarse faces (not on any active edge).
ActiveCut unbalanced_cut(TetTree& tree) {
  ActiveCut cut(tree);
  const NodeId a = cut.refine(0);
  cut.refine(a + 1);
  cut.refine(a + 6);
  const NodeId b = cut.refine(21);
  for (int k = 0; k < 8; ++k)
    cut.refine(b + k);
  return cut;
}

ActiveCut balanced_cut(TetTree& tree) {
  ActiveCut cut = unbalanced_cut(tree);
  balance_cut(cut);
  return cut;
}

using Constrained = ConstrainedCut;

Constrained constrain(const ActiveCut& cut) {
  return flatten_cut(cut);
}

bool on_box_boundary(const Vector3d& x) {
  for (int c = 0; c < 3; ++c)
    if (x[c] == kBoxMin[c] || x[c] == kBoxMax[c]) return true;
  return false;
}

Eigen::Vector4d barycentric(const Matrix3x4d& x, const Vector3d& p) {
  Matrix3d D;
  D << x.col(1) - x.col(0), x.col(2) - x.col(0), x.col(3) - x.col(0);
  const Vector3d l = D.partialPivLu().solve(p - x.col(0));
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

Matrix3x4d tet_columns(const MatrixX3d& x, const MatrixX4i& tets, Index t) {
  Matrix3x4d columns;
  for (int i = 0; i < 4; ++i)
    columns.col(i) = x.row(tets(t, i)).transpose();
  return columns;
}

// q = A X + b at the free vertices' rest positions.
VectorXd affine_q(const Constrained& c, const Matrix3d& A, const Vector3d& b) {
  VectorXd q = c.constraints.restrict_to_free(flatten(c.flat.mesh.vertices));
  for (Index i = 0; i < c.constraints.num_free(); ++i)
    q.segment<3>(3 * i) = A * q.segment<3>(3 * i) + b;
  return q;
}

Material stvk() {
  Material material;
  material.model = MaterialModel::stvk;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1200.0;
  return material;
}

TEST(HangingConstraints, DetectionMatchesPointLocation) {
  TetTree tree(test_box(), 3);
  for (const ActiveCut& cut : {unbalanced_cut(tree), balanced_cut(tree)}) {
    const Constrained c = constrain(cut);
    const MatrixX3d& X = c.flat.mesh.vertices;
    const MatrixX4i& T = c.flat.mesh.tets;
    // Brute force: a vertex hangs iff it lies in the closure of a tet that lacks it as a corner.
    // Its host: the coarsest such tet, the first in tet order among equals.
    std::vector<char> hangs(static_cast<std::size_t>(X.rows()), 0);
    std::vector<NodeId> host(static_cast<std::size_t>(X.rows()), kNoNode);
    for (Index t = 0; t < T.rows(); ++t) {
      const Matrix3x4d x = tet_columns(X, T, t);
      const NodeId node = c.flat.tet_nodes[t];
      for (Index v = 0; v < X.rows(); ++v) {
        if ((T.row(t).array() == v).any()) continue;
        if (barycentric(x, X.row(v).transpose()).minCoeff() < -1e-12) continue;
        hangs[v] = 1;
        if (host[v] == kNoNode || tree.level(node) < tree.level(host[v])) host[v] = node;
      }
    }
    Index expected = 0;
    for (Index v = 0; v < X.rows(); ++v) {
      EXPECT_EQ(c.constraints.is_hanging(static_cast<int>(v)), hangs[v] != 0) << "vertex " << v;
      expected += hangs[v];
    }
    EXPECT_GT(expected, 0);
    EXPECT_EQ(c.constraints.num_hanging(), expected);
    EXPECT_EQ(c.constraints.num_free() + c.constraints.num_hanging(), X.rows());
    // Hosts are active tets coarser than the hanging vertex's level.
    for (const HangingVertex& h : c.constraints.hanging()) {
      EXPECT_EQ(h.host, host[h.vertex]) << "vertex " << h.vertex;
      EXPECT_TRUE(cut.is_active(h.host));
      EXPECT_LT(h.host_level, tree.vertex_level(c.flat.tree_vertices[h.vertex]));
    }
  }
  // Level-2 tets next to level-0 tets make vertices a quarter along coarse edges: chains.
  EXPECT_GE(constrain(unbalanced_cut(tree)).constraints.max_chain_depth(), 2);
}

TEST(HangingConstraints, NoneOnUniformCutsOfADeeperTree) {
  TetTree tree(test_box(), 2);
  refine_uniformly(tree, 2);
  for (const ActiveCut& cut : {ActiveCut(tree), ActiveCut::uniform(tree, 1)}) {
    const Constrained c = constrain(cut);
    EXPECT_EQ(c.constraints.num_hanging(), 0);
    EXPECT_EQ(c.constraints.max_chain_depth(), 0);
    EXPECT_EQ(c.constraints.num_free(), c.flat.mesh.vertices.rows());
  }
}

TEST(HangingConstraints, EmbeddingStructure) {
  TetTree tree(test_box(), 3);
  for (const ActiveCut& cut : {unbalanced_cut(tree), balanced_cut(tree), ActiveCut(tree)}) {
    const Constrained c = constrain(cut);
    const HangingConstraints& hc = c.constraints;
    const SparseMatrixd& C = hc.matrix();
    ASSERT_EQ(C.rows(), hc.num_vertices());
    ASSERT_EQ(C.cols(), hc.num_free());
    const Eigen::MatrixXd dense = C;
    for (Index v = 0; v < C.rows(); ++v) {
      EXPECT_NEAR(dense.row(v).sum(), 1.0, 1e-15) << "row " << v;
      EXPECT_GE(dense.row(v).minCoeff(), 0.0);
      const int q = hc.free_index()[v];
      if (q >= 0) {
        EXPECT_EQ(dense(v, q), 1.0);
        EXPECT_EQ(dense.row(v).cwiseAbs().sum(), 1.0);  // an identity row
        EXPECT_EQ(hc.free_vertices()[q], v);
      }
    }
    // C reproduces the rest geometry: hanging vertices sit where their parents put them.
    const VectorXd X = flatten(c.flat.mesh.vertices);
    EXPECT_LE((hc.expand(hc.restrict_to_free(X)) - X).cwiseAbs().maxCoeff(), 1e-15);
    // expand / reduce are C ⊗ I₃ and its transpose.
    const SparseMatrixd P = hc.dof_matrix();
    const VectorXd q = VectorXd::Random(3 * hc.num_free());
    const VectorXd f = VectorXd::Random(3 * hc.num_vertices());
    EXPECT_LE((hc.expand(q) - P * q).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LE((hc.reduce(f) - P.transpose() * f).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(HangingConstraints, ConstrainedMeshIsConforming) {
  TetTree tree(test_box(), 3);
  const ActiveCut cut = balanced_cut(tree);
  const Constrained c = constrain(cut);
  const MatrixX3d x = unflatten(
      c.constraints.expand(c.constraints.restrict_to_free(flatten(c.flat.mesh.vertices))));
  const MatrixX4i& T = c.flat.mesh.tets;

  // Vertex lookup by (constrained) position, independent of the tree.
  std::map<std::array<long long, 3>, int> by_position;
  const auto key = [](const Vector3d& p) {
    return std::array<long long, 3>{std::llround(1e9 * p[0]), std::llround(1e9 * p[1]),
                                    std::llround(1e9 * p[2])};
  };
  for (Index v = 0; v < x.rows(); ++v)
    by_position[key(x.row(v).transpose())] = static_cast<int>(v);
  const auto vertex_at = [&](const Vector3d& p) {
    const auto it = by_position.find(key(p));
    return it == by_position.end() ? -1 : it->second;
  };

  std::map<std::array<int, 3>, int> face_count;
  const auto sorted = [](int a, int b, int c2) {
    std::array<int, 3> f{a, b, c2};
    std::sort(f.begin(), f.end());
    return f;
  };
  for (Index t = 0; t < T.rows(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[k++] = T(t, i);
      ++face_count[sorted(f[0], f[1], f[2])];
    }
  std::set<std::array<int, 3>> covered_by_coarse;
  std::set<std::array<int, 3>> coarse_with_children;
  Index boundary = 0;
  Index matched = 0;
  for (const auto& [f, count] : face_count) {
    ASSERT_LE(count, 2);
    if (count == 2) {
      ++matched;
      continue;
    }
    bool on_plane = false;
    for (int axis = 0; axis < 3; ++axis)
      for (const double plane : {kBoxMin[axis], kBoxMax[axis]})
        on_plane = on_plane ||
                   (x(f[0], axis) == plane && x(f[1], axis) == plane && x(f[2], axis) == plane);
    if (on_plane) {
      ++boundary;
      continue;
    }
    const int ab = vertex_at(0.5 * (x.row(f[0]) + x.row(f[1])).transpose());
    const int ac = vertex_at(0.5 * (x.row(f[0]) + x.row(f[2])).transpose());
    const int bc = vertex_at(0.5 * (x.row(f[1]) + x.row(f[2])).transpose());
    if (ab < 0 || ac < 0 || bc < 0) continue;
    const std::array<std::array<int, 3>, 4> children = {sorted(f[0], ab, ac), sorted(f[1], ab, bc),
                                                        sorted(f[2], ac, bc), sorted(ab, ac, bc)};
    bool all = true;
    for (const auto& child : children) {
      const auto it = face_count.find(child);
      all = all && it != face_count.end() && it->second == 1;
    }
    if (!all) continue;
    coarse_with_children.insert(f);
    covered_by_coarse.insert(children.begin(), children.end());
  }
  EXPECT_GT(boundary, 0);
  EXPECT_GT(matched, 0);
  EXPECT_GT(coarse_with_children.size(), 0u);
  for (const auto& [f, count] : face_count) {
    if (count == 2 || coarse_with_children.count(f) || covered_by_coarse.count(f)) continue;
    bool on_plane = false;
    for (int axis = 0; axis < 3; ++axis)
      for (const double plane : {kBoxMin[axis], kBoxMax[axis]})
        on_plane = on_plane ||
                   (x(f[0], axis) == plane && x(f[1], axis) == plane && x(f[2], axis) == plane);
    EXPECT_TRUE(on_plane) << "face " << f[0] << " " << f[1] << " " << f[2]
                          << " is neither matched, boundary nor refined across";
  }
}

// Σ tet volumes of a deformed mesh equals the volume its boundary encloses iff the tets tile the
// deformed domain without gaps or overlaps (interior faces cancel only if they match).
double volume_mismatch(const Constrained& c, ConstRef<VectorXd> deformed) {
  const MatrixX3d X = c.flat.mesh.vertices;
  const MatrixX3d x = unflatten(deformed);
  const MatrixX4i& T = c.flat.mesh.tets;
  double tets = 0.0;
  for (Index t = 0; t < T.rows(); ++t)
    tets += tet_signed_volume(x.row(T(t, 0)), x.row(T(t, 1)), x.row(T(t, 2)), x.row(T(t, 3)));
  double enclosed = 0.0;
  const MatrixX3i faces = boundary_faces(T);
  for (Index f = 0; f < faces.rows(); ++f) {
    const Vector3d centre = (X.row(faces(f, 0)) + X.row(faces(f, 1)) + X.row(faces(f, 2))) / 3.0;
    if (!on_box_boundary(centre)) continue;  // an interface with hanging vertices
    enclosed += x.row(faces(f, 0)).dot(x.row(faces(f, 1)).cross(x.row(faces(f, 2)))) / 6.0;
  }
  return std::abs(tets - enclosed) / std::abs(tets);
}

TEST(HangingConstraints, NonlinearDeformationLeavesNoGaps) {
  TetTree tree(test_box(), 3);
  for (const ActiveCut& cut : {unbalanced_cut(tree), balanced_cut(tree)}) {
    const Constrained c = constrain(cut);
    VectorXd q = c.constraints.restrict_to_free(flatten(c.flat.mesh.vertices));
    for (Index i = 0; i < c.constraints.num_free(); ++i) {
      const Vector3d p = q.segment<3>(3 * i);
      q.segment<3>(3 * i) += 0.1 * Vector3d(std::sin(3.0 * p.y() + p.z()), p.x() * p.z(),
                                            std::cos(2.0 * p.x()) * p.y());
    }
    VectorXd x = c.constraints.expand(q);
    EXPECT_LT(volume_mismatch(c, x), 1e-13);
    // Moving one interior hanging vertex off its constraint opens a gap: the check can fail.
    for (const HangingVertex& h : c.constraints.hanging()) {
      if (on_box_boundary(c.flat.mesh.vertices.row(h.vertex).transpose())) continue;
      x.segment<3>(3 * h.vertex) += Vector3d(0.011, -0.007, 0.013);
      break;
    }
    EXPECT_GT(volume_mismatch(c, x), 1e-6);
  }
}

void check_patch(const ActiveCut& cut, const Matrix3d& A) {
  const Constrained c = constrain(cut);
  const HangingConstraints& hc = c.constraints;
  const Vector3d b(0.1, -0.2, 0.05);
  const VectorXd x = hc.expand(affine_q(c, A, b));
  const MatrixX3d& X = c.flat.mesh.vertices;
  for (Index v = 0; v < X.rows(); ++v)
    EXPECT_LE((x.segment<3>(3 * v) - (A * X.row(v).transpose() + b)).norm(), 1e-14)
        << "vertex " << v;

  const ElasticModel model(X, c.flat.mesh.tets, stvk());
  const Matrix3d E = 0.5 * (A.transpose() * A - Matrix3d::Identity());
  Vector6d expected;
  expected << E(0, 0), E(1, 1), E(2, 2), E(0, 1), E(1, 2), E(0, 2);
  const TetFields fields = model.tet_fields(x);
  // E = ½(FᵀF − I) cancels against I: its round-off floor is absolute, a few ε (|F| ≈ 1).
  for (Index t = 0; t < fields.green_strain.rows(); ++t)
    EXPECT_LE((fields.green_strain.row(t).transpose() - expected).norm(),
              1e-12 * expected.norm() + 1e-14)
        << "tet " << t;

  VectorXd f;
  model.forces(x, f);
  const VectorXd fq = hc.reduce(f);
  double boundary_force = 0.0;
  double interior_force = 0.0;
  for (Index i = 0; i < hc.num_free(); ++i) {
    const double norm = fq.segment<3>(3 * i).norm();
    if (on_box_boundary(X.row(hc.free_vertices()[i]).transpose()))
      boundary_force = std::max(boundary_force, norm);
    else
      interior_force = std::max(interior_force, norm);
  }
  ASSERT_GT(boundary_force, 0.0);
  EXPECT_LE(interior_force, 1e-10 * boundary_force);
  // Without the reduction, the hanging vertices inside the box carry large forces.
  double raw_hanging = 0.0;
  for (const HangingVertex& h : hc.hanging())
    if (!on_box_boundary(X.row(h.vertex).transpose()))
      raw_hanging = std::max(raw_hanging, f.segment<3>(3 * h.vertex).norm());
  EXPECT_GT(raw_hanging, 1e-2 * boundary_force);
}

Matrix3d deformation(double amount) {
  Matrix3d M;
  M << 0.5, 0.2, -0.1,  //
      0.1, -0.3, 0.25,  //
      -0.2, 0.15, 0.4;
  return Matrix3d::Identity() + amount * M;
}

TEST(HangingConstraints, PatchTestSmallAndLargeDeformation) {
  TetTree tree(test_box(), 3);
  for (const double amount : {1e-3, 0.4}) {
    SCOPED_TRACE(amount);
    ASSERT_GT(deformation(amount).determinant(), 0.5);
    check_patch(balanced_cut(tree), deformation(amount));
    check_patch(unbalanced_cut(tree), deformation(amount));
  }
}

TEST(HangingConstraints, RigidMotionGivesNoReducedForce) {
  TetTree tree(test_box(), 3);
  const Constrained c = constrain(balanced_cut(tree));
  const Matrix3d R =
      Eigen::AngleAxisd(0.7, Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const VectorXd x = c.constraints.expand(affine_q(c, R, Vector3d(0.3, -1.0, 2.0)));
  const ElasticModel model(c.flat.mesh.vertices, c.flat.mesh.tets, stvk());
  VectorXd f;
  model.forces(x, f);
  // Scale: E · (1 m)² = 1e6 N; a 0.1 % stretch gives boundary forces of order 10–100 N.
  EXPECT_LE(c.constraints.reduce(f).cwiseAbs().maxCoeff(), 1e-12 * 1e6);
  EXPECT_LE(model.tet_fields(x).green_strain.cwiseAbs().maxCoeff(), 1e-14);
}

TEST(HangingConstraints, ReducedForceIsTheGradientOfTheReducedEnergy) {
  TetTree tree(test_box(), 3);
  const Constrained c = constrain(unbalanced_cut(tree));
  const HangingConstraints& hc = c.constraints;
  const ElasticModel model(c.flat.mesh.vertices, c.flat.mesh.tets, stvk());
  VectorXd q = affine_q(c, deformation(0.2), Vector3d::Zero());
  q += 0.01 * VectorXd::Random(q.size());  // non-affine: all tets strained differently
  VectorXd f;
  model.forces(hc.expand(q), f);
  const VectorXd fq = hc.reduce(f);
  const VectorXd d = VectorXd::Random(q.size());
  const double h = 1e-6;
  const double slope =
      (model.energy(hc.expand(q + h * d)) - model.energy(hc.expand(q - h * d))) / (2.0 * h);
  EXPECT_NEAR(slope, -fq.dot(d), 1e-6 * std::abs(slope));

  // K_q = Pᵀ K P is the derivative of −f_q.
  SparseMatrixd K;
  model.stiffness(hc.expand(q), K, false);
  const SparseMatrixd Kq = hc.reduce_matrix(K);
  ASSERT_EQ(Kq.rows(), 3 * hc.num_free());
  VectorXd f_plus;
  VectorXd f_minus;
  model.forces(hc.expand(q + h * d), f_plus);
  model.forces(hc.expand(q - h * d), f_minus);
  const VectorXd fd = -(hc.reduce(f_plus) - hc.reduce(f_minus)) / (2.0 * h);
  const VectorXd Kd = Kq * d;
  EXPECT_LE((fd - Kd).norm(), 1e-6 * Kd.norm());
}

TEST(HangingConstraints, MassIsConservedOnEveryCut) {
  TetTree tree(test_box(), 3);
  const double density = stvk().density;
  const double total = density * (kBoxMax - kBoxMin).prod();
  for (const ActiveCut& cut :
       {ActiveCut(tree), ActiveCut::uniform(tree, 1), unbalanced_cut(tree), balanced_cut(tree)}) {
    const Constrained c = constrain(cut);
    const TetRestData rest = compute_tet_rest_data(c.flat.mesh.vertices, c.flat.mesh.tets);
    const VectorXd m = lumped_vertex_mass(rest.rest_volume, c.flat.mesh.tets,
                                          c.flat.mesh.vertices.rows(), density);
    const VectorXd mq = c.constraints.reduce_scalar(m);
    EXPECT_NEAR(mq.sum(), total, 1e-12 * total);
    EXPECT_GT(mq.minCoeff(), 0.0);
    EXPECT_EQ(mq.size(), c.constraints.num_free());
  }
}

}  // namespace
}  // namespace strata
