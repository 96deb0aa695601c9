// The elastic model through an embedding x = (C ⊗ I₃) q: derivatives by finite differences,
// the reduced stiffness against an independent sparse product PᵀKP, rigid invariance, and the
// Simulation running on the embedded DOFs (equilibrium, restart continuity).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

#include "fem_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// A 2 × 1 × 1-cell box, 2 m long: the vertices of the middle plane x = 1 are tied to the
/// midpoint of their neighbours at x = 0 and x = 2 (the "hanging" rule of a coarser neighbour).
struct TiedBox {
  TetMesh mesh;
  SparseMatrixd C;
  std::vector<int> dof_vertices;

  explicit TiedBox(std::array<int, 3> cells = {2, 1, 1})
      : mesh(box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), cells)) {
    const Index n = mesh.vertices.rows();
    std::vector<int> dof_index(n, -1);
    for (Index v = 0; v < n; ++v)
      if (mesh.vertices(v, 0) != 1.0) {
        dof_index[v] = static_cast<int>(dof_vertices.size());
        dof_vertices.push_back(static_cast<int>(v));
      }
    auto find = [&](double x, double y, double z) {
      for (Index v = 0; v < n; ++v)
        if ((mesh.vertices.row(v) - Eigen::RowVector3d(x, y, z)).norm() < 1e-12)
          return static_cast<int>(v);
      return -1;
    };
    std::vector<Eigen::Triplet<double>> triplets;
    for (Index v = 0; v < n; ++v) {
      if (dof_index[v] >= 0) {
        triplets.emplace_back(v, dof_index[v], 1.0);
        continue;
      }
      const double y = mesh.vertices(v, 1), z = mesh.vertices(v, 2);
      triplets.emplace_back(v, dof_index[find(0, y, z)], 0.5);
      triplets.emplace_back(v, dof_index[find(2, y, z)], 0.5);
    }
    C.resize(n, static_cast<Index>(dof_vertices.size()));
    C.setFromTriplets(triplets.begin(), triplets.end());
  }
  SparseMatrixd P() const {
    std::vector<Eigen::Triplet<double>> triplets;
    for (Index k = 0; k < C.outerSize(); ++k)
      for (SparseMatrixd::InnerIterator it(C, k); it; ++it)
        for (int c = 0; c < 3; ++c)
          triplets.emplace_back(3 * it.row() + c, 3 * it.col() + c, it.value());
    SparseMatrixd result(3 * C.rows(), 3 * C.cols());
    result.setFromTriplets(triplets.begin(), triplets.end());
    return result;
  }
};

Material test_material(MaterialModel model) {
  Material material;
  material.model = model;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

VectorXd perturbed(const VectorXd& rest, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VectorXd q = rest;
  for (Index i = 0; i < q.size(); ++i)
    q[i] += scale * uniform(rng);
  return q;
}

TEST(EmbeddedElasticModel, ForcesAndStiffnessMatchFiniteDifferences) {
  const TiedBox box;
  for (MaterialModel kind : testing::kAllModels) {
    const ElasticModel model(box.mesh.vertices, box.mesh.tets, test_material(kind));
    const EmbeddedElasticModel embedded(model, box.C, box.dof_vertices);
    const VectorXd q = perturbed(embedded.rest_positions(), 0.05, 7);
    VectorXd f;
    embedded.forces(q, f);
    ASSERT_EQ(f.size(), embedded.num_dofs());
    SparseMatrixd K;
    embedded.stiffness(q, K, false);
    const double h = 1e-6;
    double force_error = 0.0, force_scale = f.lpNorm<Eigen::Infinity>();
    double stiffness_error = 0.0, stiffness_scale = 0.0;
    for (Index i = 0; i < q.size(); ++i) {
      VectorXd qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const double fd_force = -(embedded.energy(qp) - embedded.energy(qm)) / (2 * h);
      force_error = std::max(force_error, std::abs(fd_force - f[i]));
      VectorXd fp, fm;
      embedded.forces(qp, fp);
      embedded.forces(qm, fm);
      const VectorXd fd_column = -(fp - fm) / (2 * h);
      const VectorXd column = K.col(i);
      stiffness_error = std::max(stiffness_error, (fd_column - column).lpNorm<Eigen::Infinity>());
      stiffness_scale = std::max(stiffness_scale, column.lpNorm<Eigen::Infinity>());
    }
    EXPECT_LT(force_error, 1e-6 * force_scale) << to_string(kind);
    EXPECT_LT(stiffness_error, 1e-5 * stiffness_scale) << to_string(kind);
  }
}

TEST(EmbeddedElasticModel, ReducedStiffnessEqualsSparseTripleProduct) {
  const TiedBox box;
  const ElasticModel model(box.mesh.vertices, box.mesh.tets, test_material(MaterialModel::stvk));
  const EmbeddedElasticModel embedded(model, box.C, box.dof_vertices);
  const VectorXd q = perturbed(embedded.rest_positions(), 0.1, 3);
  SparseMatrixd K_reduced, K_mesh;
  embedded.stiffness(q, K_reduced, true);
  model.stiffness(embedded.expand(q), K_mesh, true);
  const SparseMatrixd P = box.P();
  const Eigen::MatrixXd expected = Eigen::MatrixXd(P.transpose() * K_mesh * P);
  const Eigen::MatrixXd actual = Eigen::MatrixXd(K_reduced);
  EXPECT_LT((expected - actual).lpNorm<Eigen::Infinity>(),
            1e-12 * expected.lpNorm<Eigen::Infinity>());
  // A second evaluation rewrites the values in place (no accumulation).
  embedded.stiffness(q, K_reduced, true);
  EXPECT_LT((expected - Eigen::MatrixXd(K_reduced)).lpNorm<Eigen::Infinity>(),
            1e-12 * expected.lpNorm<Eigen::Infinity>());
}

TEST(EmbeddedElasticModel, ExpandAndReduceAreTheProlongationAndItsTranspose) {
  // x = P q and r = Pᵀ f (P = C ⊗ I₃ built independently), on a box tied at its middle plane
  // and on a larger one whose vertices span several parallel chunks.
  for (const std::array<int, 3> cells : {std::array<int, 3>{2, 1, 1}, {40, 10, 10}}) {
    TiedBox box;
    if (cells[0] != 2) box = TiedBox(cells);
    const ElasticModel model(box.mesh.vertices, box.mesh.tets, test_material(MaterialModel::stvk));
    const EmbeddedElasticModel embedded(model, box.C, box.dof_vertices);
    const SparseMatrixd P = box.P();
    const VectorXd q = VectorXd::Random(P.cols());
    const VectorXd f = VectorXd::Random(P.rows());
    const VectorXd x = P * q;
    const VectorXd r = P.transpose() * f;
    EXPECT_LE((embedded.expand(q) - x).lpNorm<Eigen::Infinity>(),
              1e-15 * x.lpNorm<Eigen::Infinity>())
        << cells[0];
    EXPECT_LE((embedded.reduce(f) - r).lpNorm<Eigen::Infinity>(),
              1e-14 * r.lpNorm<Eigen::Infinity>())
        << cells[0];
  }
}

TEST(EmbeddedElasticModel, ReducedStiffnessDoesNotDependOnTheThreadCount) {
  // The layer of tets at the tied vertices adds into K by ranges of its values, in parallel: K is
  // the same to the bit at 1, 2 and 8 threads.
  const TiedBox box({40, 10, 10});
  const ElasticModel model(box.mesh.vertices, box.mesh.tets, test_material(MaterialModel::stvk));
  const EmbeddedElasticModel embedded(model, box.C, box.dof_vertices);
  const VectorXd q = perturbed(embedded.rest_positions(), 0.01, 5);
  std::vector<SparseMatrixd> K(3);
  const int threads[3] = {1, 2, 8};
  for (int i = 0; i < 3; ++i) {
    set_thread_policy({.threads = threads[i]});
    embedded.stiffness(q, K[i], false);
  }
  set_thread_policy({});
  for (int i = 1; i < 3; ++i) {
    ASSERT_EQ(K[i].nonZeros(), K[0].nonZeros());
    EXPECT_TRUE(std::equal(K[0].valuePtr(), K[0].valuePtr() + K[0].nonZeros(), K[i].valuePtr()))
        << threads[i] << " threads";
  }
}

TEST(EmbeddedElasticModel, RigidMotionOfDofsGivesNoForce) {
  const TiedBox box;
  const ElasticModel model(box.mesh.vertices, box.mesh.tets,
                           test_material(MaterialModel::neohookean));
  const EmbeddedElasticModel embedded(model, box.C, box.dof_vertices);
  std::mt19937 rng(11);
  const Matrix3d R = testing::random_rotation(rng);
  const Vector3d shift(0.3, -1.0, 2.0);
  VectorXd q = embedded.rest_positions();
  for (Index v = 0; v < q.size() / 3; ++v)
    q.segment<3>(3 * v) = R * q.segment<3>(3 * v) + shift;
  VectorXd f;
  embedded.forces(q, f);
  EXPECT_LT(f.lpNorm<Eigen::Infinity>(), 1e-6);  // E·h² = 1e6 N scale
  EXPECT_LT(std::abs(embedded.energy(q)), 1e-6);
  // The hanging vertices follow the rigid motion too.
  const VectorXd x = embedded.expand(q);
  for (Index v = 0; v < box.mesh.vertices.rows(); ++v) {
    const Vector3d expected = R * box.mesh.vertices.row(v).transpose() + shift;
    EXPECT_LT((x.segment<3>(3 * v) - expected).norm(), 1e-12);
  }
}

TEST(EmbeddedElasticModel, RejectsInvalidEmbeddings) {
  const TiedBox box;
  const ElasticModel model(box.mesh.vertices, box.mesh.tets, test_material(MaterialModel::stvk));
  SparseMatrixd bad = box.C;
  bad.coeffRef(box.dof_vertices[0], 0) = 0.5;  // row no longer sums to 1
  EXPECT_THROW(EmbeddedElasticModel(model, bad, box.dof_vertices), InputError);
  std::vector<int> wrong = box.dof_vertices;
  std::swap(wrong[0], wrong[1]);  // identity rows do not match
  EXPECT_THROW(EmbeddedElasticModel(model, box.C, wrong), InputError);
  EXPECT_THROW(EmbeddedElasticModel(model, SparseMatrixd(3, 3), {0, 1, 2}), InputError);
}

SolverSettings static_settings() {
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 2;
  return settings;
}

DirichletSpec clamp_at_x0() {
  DirichletSpec clamp;
  clamp.name = "fixed.0";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  return clamp;
}

TEST(SimulationEmbedding, StaticEquilibriumOfTheConstrainedSystem) {
  const TiedBox box;
  SimulationOptions options;
  options.vertex_embedding = box.C;
  options.dof_vertices = box.dof_vertices;
  Simulation sim(box.mesh,
                 {.material = test_material(MaterialModel::neohookean),
                  .dirichlet = {clamp_at_x0()},
                  .gravity = Vector3d(0, 0, -50.0)},
                 static_settings(), options);
  // Total mass is kept by Cᵀ m.
  EXPECT_NEAR(sim.dof_vertex_mass().sum(), sim.vertex_mass().sum(), 1e-9);
  EXPECT_NEAR(sim.vertex_mass().sum(), 1000.0 * 2.0, 1e-9);
  while (!sim.finished())
    sim.advance();
  // Mesh positions follow x = C q exactly.
  const VectorXd expanded = sim.embedded_model().expand(sim.dof_positions());
  EXPECT_LT((expanded - sim.positions()).lpNorm<Eigen::Infinity>(), 1e-15);
  // Independent check of equilibrium: the reduced residual Pᵀ(f_int(x) + f_ext,mesh) vanishes on
  // the free DOFs, computed from the mesh model and the sparse product directly.
  VectorXd f_int;
  sim.model().forces(sim.positions(), f_int);
  VectorXd f_ext = VectorXd::Zero(f_int.size());
  for (Index v = 0; v < box.mesh.vertices.rows(); ++v)
    f_ext[3 * v + 2] = -50.0 * sim.vertex_mass()[v];
  const VectorXd residual = box.P().transpose() * (f_int + f_ext);
  double worst = 0.0;
  for (Index q = 0; q < static_cast<Index>(box.dof_vertices.size()); ++q)
    if (box.mesh.vertices(box.dof_vertices[q], 0) > 0.0)
      worst = std::max(worst, residual.segment<3>(3 * q).norm());
  EXPECT_LT(worst, 1e-8 * f_ext.norm());
  // The beam sags, and the tied plane sits halfway between its neighbours.
  EXPECT_LT(sim.positions().minCoeff(), -1e-4);
  // Reactions balance the weight.
  const auto reactions = sim.reactions();
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_NEAR(reactions[0].force.z(), 50.0 * 2000.0, 1e-6 * 1e5);
}

TEST(SimulationEmbedding, RestartingFromAStepContinuesTheTrajectory) {
  const TiedBox box;
  SolverSettings settings;
  settings.integrator = Integrator::implicit_euler;
  settings.dt = 1e-3;
  settings.duration = 0.02;
  settings.ramp_time = 0.01;
  DirichletSpec pull;
  pull.name = "prescribed.0";
  pull.region = PlaneRegion{Vector3d(2, 0, 0), Vector3d::UnitX(), 0.0};
  pull.kind = DirichletKind::displacement;
  pull.displacement = Vector3d(0.02, 0.0, 0.01);
  const std::vector<DirichletSpec> groups = {clamp_at_x0(), pull};
  SimulationOptions options;
  options.vertex_embedding = box.C;
  options.dof_vertices = box.dof_vertices;
  const Material material = test_material(MaterialModel::stvk);
  Simulation reference(box.mesh, {.material = material, .dirichlet = groups}, settings, options);
  for (int i = 0; i < 8; ++i)
    reference.advance();
  SimulationOptions restart = options;
  restart.first_step = 8;
  Simulation resumed(box.mesh, {.material = material, .dirichlet = groups}, settings, restart);
  EXPECT_DOUBLE_EQ(resumed.time(), reference.time());
  resumed.set_state(reference.dof_positions(), reference.dof_velocities());
  while (!reference.finished()) {
    reference.advance();
    resumed.advance();
  }
  EXPECT_TRUE(resumed.finished());
  EXPECT_EQ(resumed.counters().steps, reference.counters().steps - 8);
  EXPECT_LT((resumed.positions() - reference.positions()).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((resumed.velocities() - reference.velocities()).lpNorm<Eigen::Infinity>(), 1e-9);
}

}  // namespace
}  // namespace strata
