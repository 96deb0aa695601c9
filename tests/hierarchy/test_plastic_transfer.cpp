// Plastic state across cut changes (transfer_plastic_state): refined tets inherit their parent's
// state, merged parents get the volume-weighted mean, and a run whose cut is refined or coarsened
// mid-way continues exactly as a run on the new cut from the start (a uniaxial bar, whose linear
// displacement field every cut represents).
#include <gtest/gtest.h>

#include <cmath>

#include "strata/core/sim/simulation.hpp"
#include "strata/hierarchy/active_cut.hpp"
#include "strata/hierarchy/cut_transfer.hpp"
#include "strata/hierarchy/tree_flatten.hpp"

namespace strata {
namespace {

constexpr double kE = 1e7, kYield = 1e4, kLength = 1.0, kWidth = 0.2;

PlasticState numbered_state(Index num_tets) {
  PlasticState state = PlasticState::identity(num_tets);
  for (Index t = 0; t < num_tets; ++t) {
    state.equivalent_strain[t] = 1e-3 * static_cast<double>(t + 1);
    Matrix3d shear = Matrix3d::Identity();
    shear(0, 1) = 1e-3 * static_cast<double>(t + 1);  // det 1
    state.plastic_inverse[t] = shear;
  }
  return state;
}

double node_volume(const TetTree& tree, NodeId n) {
  const Matrix3x4d x = tree.tet_positions(n);
  return std::abs((x.col(1) - x.col(0)).dot((x.col(2) - x.col(0)).cross(x.col(3) - x.col(0)))) /
         6.0;
}

TEST(PlasticTransfer, RefinedTetsInheritAndMergedParentsAverage) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(1.0, 1.0, 1.0), {1, 1, 1}), 2);
  ActiveCut cut(tree);
  const FlatTreeMesh roots = flatten_nodes(tree, cut.nodes());
  const PlasticState root_state = numbered_state(static_cast<Index>(roots.tet_nodes.size()));
  cut.refine(2);
  const FlatTreeMesh refined = flatten_nodes(tree, cut.nodes());
  double change = -1.0;
  const PlasticState refined_state =
      transfer_plastic_state(tree, roots, root_state, refined, &change);
  EXPECT_EQ(change, 0.0);
  for (std::size_t t = 0; t < refined.tet_nodes.size(); ++t) {
    NodeId n = refined.tet_nodes[t];
    while (tree.parent(n) != kNoNode)
      n = tree.parent(n);
    std::size_t root_tet = 0;
    while (roots.tet_nodes[root_tet] != n)
      ++root_tet;
    EXPECT_EQ(refined_state.equivalent_strain[t], root_state.equivalent_strain[root_tet]);
    EXPECT_EQ(refined_state.plastic_inverse[t], root_state.plastic_inverse[root_tet]);
  }

  // Give the children distinct states, then merge them.
  PlasticState varied = numbered_state(static_cast<Index>(refined.tet_nodes.size()));
  cut.coarsen(2);
  const FlatTreeMesh merged = flatten_nodes(tree, cut.nodes());
  const PlasticState merged_state = transfer_plastic_state(tree, refined, varied, merged, &change);
  double volume = 0.0, strain = 0.0, largest = 0.0;
  Matrix3d mean = Matrix3d::Zero();
  for (std::size_t t = 0; t < refined.tet_nodes.size(); ++t) {
    if (tree.parent(refined.tet_nodes[t]) != 2) continue;
    const double v = node_volume(tree, refined.tet_nodes[t]);
    volume += v;
    strain += v * varied.equivalent_strain[t];
    mean += v * varied.plastic_inverse[t];
  }
  ASSERT_GT(volume, 0.0);
  strain /= volume;
  mean /= volume;
  for (std::size_t t = 0; t < refined.tet_nodes.size(); ++t)
    if (tree.parent(refined.tet_nodes[t]) == 2)
      largest = std::max(largest, std::abs(varied.equivalent_strain[t] - strain));
  for (std::size_t t = 0; t < merged.tet_nodes.size(); ++t) {
    if (merged.tet_nodes[t] != 2) continue;
    EXPECT_NEAR(merged_state.equivalent_strain[t], strain, 1e-15);
    EXPECT_NEAR(merged_state.plastic_inverse[t].determinant(), 1.0, 1e-14);
    EXPECT_LE((merged_state.plastic_inverse[t] - mean / std::cbrt(mean.determinant()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-15);
  }
  EXPECT_NEAR(change, largest, 1e-15);
}

/// The uniaxial bar on the symmetry planes y = 0, z = 0, x = 0, pulled to 4 yield strains in x
/// at x = L and let back to 1 over 8 static load steps, with hardening.
struct BarRun {
  std::vector<DirichletSpec> groups;
  Material material;
  SolverSettings settings;
  BarRun() {
    for (int axis : {1, 2, 0}) {
      DirichletSpec spec;
      spec.name = "symmetry";
      spec.region = PlaneRegion{Vector3d::Zero(), Vector3d::Unit(axis), 0.0};
      spec.components = {axis == 0, axis == 1, axis == 2};
      groups.push_back(spec);
    }
    DirichletSpec pull;
    pull.name = "pull";
    pull.region = PlaneRegion{Vector3d(kLength, 0, 0), Vector3d::UnitX(), 0.0};
    pull.kind = DirichletKind::displacement;
    pull.displacement = Vector3d(4 * kYield / kE * kLength, 0, 0);
    pull.components = {true, false, false};
    pull.amplitude.points = {{0.0, 0.0}, {0.5, 1.0}, {1.0, 0.25}};
    groups.push_back(pull);
    material.model = MaterialModel::neohookean;
    material.youngs_modulus = kE;
    material.poisson_ratio = 0.3;
    material.plasticity = Plasticity{kYield, 0.05 * kE};
    settings.mode = SimulationMode::static_equilibrium;
    settings.load_steps = 8;
    settings.plasticity.tolerance = 1e-6;
  }
  std::unique_ptr<Simulation> make(const FlatTreeMesh& flat, long first_step = 0,
                                   PlasticState state = {}) const {
    SimulationOptions options;
    options.first_step = first_step;
    options.plastic_state = std::move(state);
    return std::make_unique<Simulation>(flat.mesh,
                                        ProblemSpec{.material = material, .dirichlet = groups},
                                        settings, std::move(options));
  }
};

/// Largest |x − x_reference| over the vertices of `flat` (positions of `reference_flat`'s mesh
/// carried by tree vertex id).
double position_difference(const FlatTreeMesh& flat, const VectorXd& x,
                           const FlatTreeMesh& reference_flat, const VectorXd& reference) {
  double largest = 0.0;
  for (std::size_t v = 0; v < flat.tree_vertices.size(); ++v) {
    const int r = reference_flat.mesh_vertices[flat.tree_vertices[v]];
    if (r < 0) continue;
    largest = std::max(largest, (x.segment<3>(3 * static_cast<Index>(v)) -
                                 reference.segment<3>(3 * static_cast<Index>(r)))
                                    .cwiseAbs()
                                    .maxCoeff());
  }
  return largest;
}

TEST(PlasticTransfer, RefiningMidRunContinuesAsTheFineRun) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(kLength, kWidth, kWidth), {4, 1, 1}), 1);
  ActiveCut cut(tree);
  const FlatTreeMesh coarse = flatten_nodes(tree, cut.nodes());
  for (NodeId n : std::vector<NodeId>(cut.nodes()))
    cut.refine(n);
  const FlatTreeMesh fine = flatten_nodes(tree, cut.nodes());
  const BarRun bar;

  // Reference: the fine cut from the start.
  std::unique_ptr<Simulation> reference = bar.make(fine);
  while (!reference->finished())
    reference->advance();

  // Coarse for 6 load steps (yielding from step 2, unloading from step 5), then refined.
  std::unique_ptr<Simulation> run = bar.make(coarse);
  for (int k = 0; k < 6; ++k)
    run->advance();
  ASSERT_GT(run->plastic_state().equivalent_strain.minCoeff(), 0.0);
  const VectorXd x = transfer_vertex_values(tree, coarse, run->positions(), fine);
  PlasticState state = transfer_plastic_state(tree, coarse, run->plastic_state(), fine);
  run = bar.make(fine, 6, std::move(state));
  run->set_state(x, VectorXd::Zero(x.size()));
  run->resolve_static();
  while (!run->finished())
    run->advance();
  const double peak = 4 * kYield / kE * kLength;
  EXPECT_LE(position_difference(fine, run->positions(), fine, reference->positions()), 1e-6 * peak);
  EXPECT_LE((run->plastic_state().equivalent_strain - reference->plastic_state().equivalent_strain)
                .cwiseAbs()
                .maxCoeff(),
            1e-6 * reference->plastic_state().equivalent_strain.maxCoeff());

  // Without the inherited state the refined run would restart virgin, partly unloaded, and end
  // far off.
  std::unique_ptr<Simulation> virgin = bar.make(fine, 6);
  virgin->set_state(x, VectorXd::Zero(x.size()));
  virgin->resolve_static();
  while (!virgin->finished())
    virgin->advance();
  EXPECT_GT(
      (virgin->plastic_state().equivalent_strain - reference->plastic_state().equivalent_strain)
          .cwiseAbs()
          .maxCoeff(),
      0.1 * reference->plastic_state().equivalent_strain.maxCoeff());
}

TEST(PlasticTransfer, CoarseningMidRunContinuesAsTheCoarseRun) {
  TetTree tree(box_tet_mesh(Vector3d::Zero(), Vector3d(kLength, kWidth, kWidth), {4, 1, 1}), 1);
  ActiveCut cut(tree);
  const FlatTreeMesh coarse = flatten_nodes(tree, cut.nodes());
  const std::vector<NodeId> roots = cut.nodes();
  for (NodeId n : roots)
    cut.refine(n);
  const FlatTreeMesh fine = flatten_nodes(tree, cut.nodes());
  const BarRun bar;
  std::unique_ptr<Simulation> reference = bar.make(coarse);
  while (!reference->finished())
    reference->advance();
  std::unique_ptr<Simulation> run = bar.make(fine);
  for (int k = 0; k < 6; ++k)
    run->advance();
  double change = -1.0;
  PlasticState state = transfer_plastic_state(tree, fine, run->plastic_state(), coarse, &change);
  EXPECT_LE(change, 1e-9);  // a uniform state merges without loss
  const VectorXd x = transfer_vertex_values(tree, fine, run->positions(), coarse);
  run = bar.make(coarse, 6, std::move(state));
  run->set_state(x, VectorXd::Zero(x.size()));
  run->resolve_static();
  while (!run->finished())
    run->advance();
  const double peak = 4 * kYield / kE * kLength;
  EXPECT_LE(position_difference(coarse, run->positions(), coarse, reference->positions()),
            1e-6 * peak);
}

}  // namespace
}  // namespace strata
