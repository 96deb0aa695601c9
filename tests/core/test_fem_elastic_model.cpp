// Mesh-level forces and stiffness: finite differences, an independent dense assembly, thread-count
// independence, rigid motion, the patch test on an irregular mesh, and lumped mass.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>

#include "fem_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/fem/material_registry.hpp"
#include "strata/core/fem/tet_element.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

using testing::kAllModels;
using testing::random_deformation_gradient;
using testing::random_rotation;

/// A box mesh whose interior vertices are jittered: an irregular mesh with a flat boundary.
TetMesh irregular_box(int n, std::uint32_t seed) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 1.0), {n, n, n});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2 / n, 0.2 / n);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const auto p = mesh.vertices.row(v);
    const bool interior = (p.array() > 1e-12).all() && (p.array() < 1 - 1e-12).all();
    if (interior)
      for (int k = 0; k < 3; ++k)
        mesh.vertices(v, k) += jitter(rng);
  }
  return mesh;
}

Material test_material(MaterialModel model) {
  Material material;
  material.model = model;
  material.youngs_modulus = 1e5;
  material.poisson_ratio = 0.35;
  material.density = 1000.0;
  return material;
}

VectorXd randomly_deformed(const VectorXd& rest, std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
  VectorXd x = rest;
  for (Index i = 0; i < x.size(); ++i)
    x[i] += uniform(rng);
  return x;
}

class ElasticModelTest : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(ElasticModelTest, ForcesMatchFiniteDifferenceOfEnergy) {
  const TetMesh mesh = irregular_box(2, 1);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(2);
  const VectorXd x = randomly_deformed(model.rest_positions(), rng, 0.05);
  VectorXd f;
  const double energy = model.energy_and_forces(x, f);
  EXPECT_NEAR(energy, model.energy(x), 1e-12 * std::abs(energy));
  const double h = 1e-7;
  for (Index i = 0; i < x.size(); ++i) {
    VectorXd plus = x, minus = x;
    plus[i] += h;
    minus[i] -= h;
    const double fd = -(model.energy(plus) - model.energy(minus)) / (2 * h);
    EXPECT_NEAR(f[i], fd, 1e-5 * f.cwiseAbs().maxCoeff()) << "dof " << i;
  }
}

TEST_P(ElasticModelTest, ForcesAndEnergyEqualElementAssemblyIncludingPartialLaneGroups) {
  // 157 tets: not a multiple of the kernels' lane width, so the scalar tail runs too.
  TetMesh mesh = irregular_box(3, 12);
  mesh.tets.conservativeResize(157, 4);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(13);
  const VectorXd x = randomly_deformed(model.rest_positions(), rng, 0.03);
  VectorXd f;
  const double energy = model.energy_and_forces(x, f);
  VectorXd reference = VectorXd::Zero(x.size());
  double reference_energy = 0.0;
  const LameParameters lame = model.material().lame();
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    Vector12d xt;
    for (int k = 0; k < 4; ++k)
      xt.segment<3>(3 * k) = x.segment<3>(3 * mesh.tets(t, k));
    const Matrix3d& Dm_inv = model.rest_data().Dm_inv[t];
    const double volume = model.rest_data().rest_volume[t];
    const Vector12d g = tet_gradient(GetParam(), lame, xt, Dm_inv, volume);
    reference_energy += tet_energy(GetParam(), lame, xt, Dm_inv, volume);
    for (int k = 0; k < 4; ++k)
      reference.segment<3>(3 * mesh.tets(t, k)) -= g.segment<3>(3 * k);
  }
  EXPECT_LT((f - reference).norm(), 1e-12 * reference.norm());
  EXPECT_NEAR(energy, reference_energy, 1e-12 * std::abs(reference_energy));
  EXPECT_NEAR(model.energy(x), reference_energy, 1e-12 * std::abs(reference_energy));
}

TEST_P(ElasticModelTest, StiffnessMatchesFiniteDifferenceOfForcesAndDenseAssembly) {
  const TetMesh mesh = irregular_box(2, 3);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(4);
  const VectorXd x = randomly_deformed(model.rest_positions(), rng, 0.05);
  SparseMatrixd K;
  model.stiffness(x, K, false);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(K);
  EXPECT_LT((dense - dense.transpose()).norm(), 1e-9 * dense.norm());

  // Independent assembly from the element Hessians.
  Eigen::MatrixXd reference = Eigen::MatrixXd::Zero(x.size(), x.size());
  const LameParameters lame = model.material().lame();
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    Vector12d xt;
    for (int k = 0; k < 4; ++k)
      xt.segment<3>(3 * k) = x.segment<3>(3 * mesh.tets(t, k));
    const Matrix12d H = tet_hessian(GetParam(), lame, xt, model.rest_data().Dm_inv[t],
                                    model.rest_data().rest_volume[t]);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        reference.block<3, 3>(3 * mesh.tets(t, a), 3 * mesh.tets(t, b)) +=
            H.block<3, 3>(3 * a, 3 * b);
  }
  EXPECT_LT((dense - reference).norm(), 1e-10 * reference.norm());

  const double h = 1e-7;
  VectorXd f_plus, f_minus;
  for (Index i = 0; i < x.size(); i += 5) {
    VectorXd plus = x, minus = x;
    plus[i] += h;
    minus[i] -= h;
    model.forces(plus, f_plus);
    model.forces(minus, f_minus);
    const VectorXd fd = -(f_plus - f_minus) / (2 * h);
    EXPECT_LT((dense.col(i) - fd).norm(), 1e-5 * dense.norm()) << "column " << i;
  }
}

TEST_P(ElasticModelTest, EnergyFollowsThePlasticInverse) {
  // Σ V ψ(Ds Dm⁻¹ Fp⁻¹) per tet through the registry's ψ, for two plastic states in turn (the
  // second replaces the first); 157 tets, so lane groups and a scalar tail.
  TetMesh mesh = irregular_box(3, 12);
  mesh.tets.conservativeResize(157, 4);
  ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(21);
  const VectorXd x = randomly_deformed(model.rest_positions(), rng, 0.03);
  const LameParameters lame = model.material().lame();
  std::uniform_real_distribution<double> uniform(-0.05, 0.05);
  for (int state = 0; state < 2; ++state) {
    std::vector<Matrix3d> plastic_inverse(mesh.tets.rows());
    for (Matrix3d& Fp_inv : plastic_inverse)
      Fp_inv = Matrix3d::Identity() + Matrix3d::NullaryExpr([&] { return uniform(rng); });
    model.set_plastic_inverse(plastic_inverse);
    double expected = 0.0;
    for (Index t = 0; t < mesh.tets.rows(); ++t) {
      Matrix3d Ds;
      for (int k = 0; k < 3; ++k)
        Ds.col(k) = x.segment<3>(3 * mesh.tets(t, k + 1)) - x.segment<3>(3 * mesh.tets(t, 0));
      const Matrix3d F = Ds * model.rest_data().Dm_inv[t] * plastic_inverse[t];
      expected +=
          model.rest_data().rest_volume[t] * material_traits(GetParam()).energy_density(F, lame);
    }
    EXPECT_NEAR(model.energy(x), expected, 1e-12 * std::abs(expected)) << "state " << state;
  }
}

TEST_P(ElasticModelTest, ResultsAreBitwiseIdenticalForOneAndTwoThreads) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(2.0, 1.0, 1.0), {16, 8, 8});
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(5);
  const VectorXd x = randomly_deformed(model.rest_positions(), rng, 0.01);
  VectorXd f1, f2;
  SparseMatrixd K1, K2;
  double e1, e2, energy1, energy2;
  {
    ThreadLimit limit(1);
    e1 = model.energy_and_forces(x, f1);
    energy1 = model.energy(x);
    model.stiffness(x, K1, true);
  }
  {
    ThreadLimit limit(2);
    e2 = model.energy_and_forces(x, f2);
    energy2 = model.energy(x);
    model.stiffness(x, K2, true);
  }
  EXPECT_EQ(e1, e2);
  EXPECT_EQ(energy1, energy2);
  EXPECT_TRUE(f1 == f2);
  ASSERT_EQ(K1.nonZeros(), K2.nonZeros());
  EXPECT_TRUE(std::equal(K1.valuePtr(), K1.valuePtr() + K1.nonZeros(), K2.valuePtr()));
}

TEST_P(ElasticModelTest, RigidMotionGivesZeroForcesOnTheMesh) {
  const TetMesh mesh = irregular_box(3, 6);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(7);
  const Matrix3d R = random_rotation(rng);
  VectorXd x(model.num_dofs());
  for (Index v = 0; v < model.num_vertices(); ++v)
    x.segment<3>(3 * v) = R * mesh.vertices.row(v).transpose() + Vector3d(1, 2, 3);
  VectorXd f;
  const double energy = model.energy_and_forces(x, f);
  EXPECT_NEAR(energy, 0.0, 1e-12 * model.material().youngs_modulus);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-9 * model.material().youngs_modulus / 9.0);
}

TEST_P(ElasticModelTest, PatchTestLinearFieldGivesConstantStrainAndNoInteriorForce) {
  const TetMesh mesh = irregular_box(4, 8);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(9);
  const Matrix3d A = random_deformation_gradient(rng, 0.1);
  const Vector3d b(0.1, -0.2, 0.3);
  VectorXd x(model.num_dofs());
  for (Index v = 0; v < model.num_vertices(); ++v)
    x.segment<3>(3 * v) = A * mesh.vertices.row(v).transpose() + b;

  const TetFields fields = model.tet_fields(x);
  const Eigen::Matrix<double, 1, 6> strain0 = fields.green_strain.row(0);
  for (Index t = 1; t < model.num_tets(); ++t)
    EXPECT_LT((fields.green_strain.row(t) - strain0).norm(), 1e-12 * strain0.norm());

  VectorXd f;
  model.forces(x, f);
  double max_boundary_force = 0.0;
  for (Index v = 0; v < model.num_vertices(); ++v) {
    const auto p = mesh.vertices.row(v);
    const bool interior = (p.array() > 1e-12).all() && (p.array() < 1 - 1e-12).all();
    if (!interior) max_boundary_force = std::max(max_boundary_force, f.segment<3>(3 * v).norm());
  }
  ASSERT_GT(max_boundary_force, 0.0);
  for (Index v = 0; v < model.num_vertices(); ++v) {
    const auto p = mesh.vertices.row(v);
    const bool interior = (p.array() > 1e-12).all() && (p.array() < 1 - 1e-12).all();
    if (interior) {
      EXPECT_LT(f.segment<3>(3 * v).norm(), 1e-10 * max_boundary_force) << "vertex " << v;
    }
  }
}

TEST_P(ElasticModelTest, GreenStrainsAloneAreThoseOfTheFieldsAndOfTheAffineMap) {
  const TetMesh mesh = irregular_box(4, 8);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(GetParam()));
  std::mt19937 rng(11);
  const Matrix3d A = random_deformation_gradient(rng, 0.2);
  VectorXd x(model.num_dofs());
  for (Index v = 0; v < model.num_vertices(); ++v)
    x.segment<3>(3 * v) = A * mesh.vertices.row(v).transpose() + Vector3d(0.3, 0.1, -0.2);
  const Eigen::Matrix<double, Eigen::Dynamic, 6> strains = model.green_strains(x);
  EXPECT_EQ(strains, model.tet_fields(x).green_strain);  // the same bits
  // E = ½ (AᵀA − I), Voigt [xx yy zz xy yz xz] of the tensor components.
  const Matrix3d E = 0.5 * (A.transpose() * A - Matrix3d::Identity());
  Eigen::Matrix<double, 1, 6> expected;
  expected << E(0, 0), E(1, 1), E(2, 2), E(0, 1), E(1, 2), E(0, 2);
  for (Index t = 0; t < model.num_tets(); ++t)
    EXPECT_LT((strains.row(t) - expected).norm(), 1e-12 * expected.norm()) << "tet " << t;
}

INSTANTIATE_TEST_SUITE_P(AllModels, ElasticModelTest, ::testing::ValuesIn(kAllModels),
                         [](const auto& info) { return to_string(info.param); });

TEST(ElasticModel, MinVolumeRatioFindsTheInvertedTet) {
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {2, 2, 2});
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(MaterialModel::stvk));
  VectorXd x = model.rest_positions();
  EXPECT_NEAR(model.min_volume_ratio(x).first, 1.0, 1e-12);
  // Push the centre vertex (1 of 27, at (0.5, 0.5, 0.5)) far out: some tets invert.
  x.segment<3>(3 * 13) = Vector3d(3.0, 0.5, 0.5);
  const auto [J, tet] = model.min_volume_ratio(x);
  EXPECT_LT(J, 0.0);
  bool contains_centre = false;
  for (int k = 0; k < 4; ++k)
    contains_centre |= mesh.tets(tet, k) == 13;
  EXPECT_TRUE(contains_centre);
}

/// The message of the InputError that building a model of `mesh` throws ("" if none).
std::string construction_error(const TetMesh& mesh) {
  try {
    const ElasticModel model(mesh.vertices, mesh.tets, test_material(MaterialModel::stvk));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ElasticModel, BadTetsAreReportedByIndexWhateverTheThreadCount) {
  // The rest data and the tet partition are built side by side; the partition must not read
  // through an index out of range, and the rest data names the first bad tet.
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {6, 6, 6});
  ASSERT_EQ(construction_error(mesh), "");
  TetMesh out_of_range = mesh;
  out_of_range.tets(700, 2) = static_cast<int>(mesh.vertices.rows()) + 5;
  out_of_range.tets(900, 1) = -3;
  TetMesh far_out = mesh;  // far enough to fault if the partition read through it
  far_out.tets(10, 0) = 1 << 30;
  TetMesh no_vertices = mesh;  // the partition's bounding box has nothing to bound
  no_vertices.vertices.resize(0, 3);
  TetMesh inverted = mesh;
  std::swap(inverted.tets(400, 1), inverted.tets(400, 2));
  // A non-finite coordinate: the first tet holding that vertex is degenerate.
  TetMesh not_finite = mesh;
  const int bad_vertex = mesh.tets(300, 2);
  not_finite.vertices(bad_vertex, 1) = std::numeric_limits<double>::quiet_NaN();
  Index first_holder = 0;
  while (!(mesh.tets.row(first_holder).array() == bad_vertex).any())
    ++first_holder;
  for (const int threads : {1, 2}) {
    const ThreadLimit limit(threads);
    EXPECT_EQ(
        construction_error(out_of_range),
        "tet 700: vertex index " + std::to_string(mesh.vertices.rows() + 5) + " out of range");
    EXPECT_EQ(construction_error(far_out),
              "tet 10: vertex index " + std::to_string(1 << 30) + " out of range");
    EXPECT_EQ(construction_error(no_vertices),
              "tet 0: vertex index " + std::to_string(mesh.tets(0, 0)) + " out of range");
    EXPECT_EQ(construction_error(inverted), "tet 400 is inverted at rest");
    EXPECT_EQ(construction_error(not_finite),
              "tet " + std::to_string(first_holder) + " is degenerate at rest");
  }
}

TEST(ElasticModel, ForcesAndMinVolumeRatioInOnePass) {
  // Every model (lane kernels and the scalar path; the 270 tets of 3 × 3 × 5 cells leave a
  // partial lane group at the end), a smooth deformation and one with inverted tets.
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 1.3), {3, 3, 5});
  for (MaterialModel material : kAllModels) {
    const ElasticModel model(mesh.vertices, mesh.tets, test_material(material));
    VectorXd x = model.rest_positions();
    for (Index v = 0; v < model.num_vertices(); ++v)
      x.segment<3>(3 * v) += 0.05 * Vector3d(std::sin(3.0 * x[3 * v + 2]), x[3 * v] * x[3 * v + 1],
                                             std::cos(2.0 * x[3 * v]));
    for (bool invert : {false, true}) {
      if (invert) x.segment<3>(3 * 31) += Vector3d(0.9, 0.2, -0.4);
      VectorXd f_plain, f_fused;
      model.forces(x, f_plain);
      const auto [J, tet] = model.forces_and_min_volume_ratio(x, f_fused);
      EXPECT_EQ(f_fused, f_plain) << to_string(material);  // the same kernel, bit for bit
      const auto [J_separate, tet_separate] = model.min_volume_ratio(x);
      EXPECT_NEAR(J, J_separate, 1e-12) << to_string(material);
      EXPECT_EQ(tet, tet_separate) << to_string(material);
      EXPECT_EQ(J < 0.0, invert) << to_string(material);
    }
  }
}

TEST(LumpedMass, SumsToDensityTimesVolume) {
  const TetMesh mesh = irregular_box(3, 10);
  const ElasticModel model(mesh.vertices, mesh.tets, test_material(MaterialModel::stvk));
  const VectorXd mass =
      lumped_vertex_mass(model.rest_data().rest_volume, mesh.tets, model.num_vertices(), 1000.0);
  EXPECT_NEAR(mass.sum(), 1000.0 * 1.0, 1e-10);
  EXPECT_GT(mass.minCoeff(), 0.0);
}

}  // namespace
}  // namespace strata
