// Review: static runs restarted mid-path (SimulationOptions::first_step) with an embedding, a
// prescribed displacement ramped by the load factor and a ground plane, against the same run
// without a restart — including the adaptive driver's pattern (re-solve the step just taken).
#include <gtest/gtest.h>

#include <algorithm>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

/// A 4 × 1 × 1-cell box, 2 m long, whose middle plane x = 1 is tied to the midpoints of its
/// neighbours at x = 0.5 and x = 1.5 (a hanging plane).
struct TiedBar {
  TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(2, 1, 1), {4, 1, 1});
  SimulationOptions options;

  TiedBar() {
    const Index n = mesh.vertices.rows();
    std::vector<int> dof_index(n, -1);
    for (Index v = 0; v < n; ++v)
      if (mesh.vertices(v, 0) != 1.0) {
        dof_index[v] = static_cast<int>(options.dof_vertices.size());
        options.dof_vertices.push_back(static_cast<int>(v));
      }
    const auto find = [&](double x, double y, double z) {
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
      triplets.emplace_back(v, dof_index[find(0.5, y, z)], 0.5);
      triplets.emplace_back(v, dof_index[find(1.5, y, z)], 0.5);
    }
    options.vertex_embedding.resize(n, static_cast<Index>(options.dof_vertices.size()));
    options.vertex_embedding.setFromTriplets(triplets.begin(), triplets.end());
  }
};

Material soft_rubber() {
  Material material;
  material.model = MaterialModel::neohookean;
  material.youngs_modulus = 2e5;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

std::vector<DirichletSpec> clamp_and_push() {
  DirichletSpec clamp;
  clamp.name = "fixed.0";
  clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
  DirichletSpec push;
  push.name = "prescribed.0";
  push.region = PlaneRegion{Vector3d(2, 0, 0), Vector3d::UnitX(), 0.0};
  push.kind = DirichletKind::displacement;
  push.displacement = Vector3d(-0.1, 0.0, -0.15);
  return {clamp, push};
}

TEST(ReviewStaticRestart, ResolvingTheLastStepOnARestartContinuesThePath) {
  const TiedBar bar;
  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 6;
  const GroundPlane ground{Vector3d(0, 0, -0.05), Vector3d::UnitZ()};
  const Vector3d gravity(0, 0, -9.81);
  Simulation reference(bar.mesh,
                       {.material = soft_rubber(),
                        .dirichlet = clamp_and_push(),
                        .gravity = gravity,
                        .ground = ground},
                       settings, bar.options);
  for (int k = 0; k < 3; ++k)
    reference.advance();
  const VectorXd q3 = reference.dof_positions();
  const double energy3 = reference.elastic_energy();
  const std::vector<GroupReaction> reactions3 = reference.reactions();

  // The adaptive driver's restart: first_step = k − 1 from the state of step k, then re-solve k.
  SimulationOptions restart = bar.options;
  restart.first_step = 2;
  Simulation resumed(bar.mesh,
                     {.material = soft_rubber(),
                      .dirichlet = clamp_and_push(),
                      .gravity = gravity,
                      .ground = ground},
                     settings, restart);
  EXPECT_DOUBLE_EQ(resumed.load_factor(), 2.0 / 6.0);
  resumed.set_state(q3, VectorXd::Zero(q3.size()));
  resumed.advance();
  EXPECT_DOUBLE_EQ(resumed.load_factor(), reference.load_factor());
  const double scale = (q3 - reference.embedded_model().rest_positions()).lpNorm<Eigen::Infinity>();
  ASSERT_GT(scale, 0.05);
  EXPECT_LT((resumed.dof_positions() - q3).lpNorm<Eigen::Infinity>(), 1e-9 * scale);
  EXPECT_NEAR(resumed.elastic_energy(), energy3, 1e-9 * energy3);
  const std::vector<GroupReaction> reactions = resumed.reactions();
  ASSERT_EQ(reactions.size(), reactions3.size());
  for (size_t g = 0; g < reactions.size(); ++g)
    EXPECT_LT((reactions[g].force - reactions3[g].force).norm(), 1e-6 * reactions3[g].force.norm());

  // Both continue to the end of the load path and agree.
  while (!reference.finished()) {
    reference.advance();
    resumed.advance();
  }
  EXPECT_TRUE(resumed.finished());
  EXPECT_EQ(resumed.counters().steps, 4);
  EXPECT_LT((resumed.positions() - reference.positions()).lpNorm<Eigen::Infinity>(), 1e-8 * scale);
  // The free part reaches the ground: penalty contact, with a small penetration only.
  double lowest = 0.0;
  for (Index v = 0; v < bar.mesh.vertices.rows(); ++v)
    if (bar.mesh.vertices(v, 0) < 2.0) lowest = std::min(lowest, resumed.positions()[3 * v + 2]);
  EXPECT_LT(lowest, -0.0499);
  EXPECT_GT(lowest, -0.052);
  // The hanging plane follows x = C q.
  EXPECT_LT((resumed.embedded_model().expand(resumed.dof_positions()) - resumed.positions())
                .lpNorm<Eigen::Infinity>(),
            1e-15);
}

}  // namespace
}  // namespace strata
