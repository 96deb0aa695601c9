#include <gtest/gtest.h>

#include "fem_test_utils.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata {
namespace {

DirichletSpec roller(const std::string& name, const Region& region,
                     std::array<bool, 3> components) {
  DirichletSpec spec;
  spec.name = name;
  spec.region = region;
  spec.components = components;
  return spec;
}

/// Static uniaxial tension of a 1 × 0.4 × 0.4 bar by a prescribed end displacement (strain 1e-4):
/// the end faces are rollers (only x prescribed), the corner (0,0,0) is pinned and (0,W,0) is held
/// in z, which removes exactly the rigid motions and leaves the lateral contraction free.
class UniaxialTension : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(UniaxialTension, PoissonRatioAndYoungsModulusAreRecovered) {
  const double L = 1.0, W = 0.4, strain = 1e-4;
  const TetMesh mesh = box_tet_mesh(Vector3d(0, 0, 0), Vector3d(L, W, W), {3, 2, 2});
  Material material;
  material.model = GetParam();
  material.youngs_modulus = 2e6;
  material.poisson_ratio = 0.35;

  std::vector<DirichletSpec> groups;
  groups.push_back(roller("fixed[0]", PlaneRegion{Vector3d(0, 0, 0), Vector3d(1, 0, 0), 0.0},
                          {true, false, false}));
  groups.push_back(roller("fixed[1]", SphereRegion{Vector3d(0, 0, 0), 0.0}, {true, true, true}));
  groups.push_back(roller("fixed[2]", SphereRegion{Vector3d(0, W, 0), 0.0}, {true, false, true}));
  DirichletSpec pull =
      roller("displacement[0]", PlaneRegion{Vector3d(L, 0, 0), Vector3d(1, 0, 0), 0.0},
             {true, false, false});
  pull.kind = DirichletKind::displacement;
  pull.displacement = Vector3d(strain * L, 0, 0);
  groups.push_back(pull);

  SolverSettings settings;
  settings.mode = SimulationMode::static_equilibrium;
  settings.load_steps = 1;
  Simulation sim(mesh, {.material = material, .dirichlet = groups}, settings);
  while (!sim.finished())
    sim.advance();

  // Lateral strain from the displacements of all vertices on y = W and z = W relative to y, z = 0.
  const VectorXd& x = sim.positions();
  double lateral_sum = 0.0;
  int lateral_count = 0;
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    for (int axis : {1, 2}) {
      const double X = mesh.vertices(v, axis);
      if (X < 1e-12) continue;
      lateral_sum += (x[3 * v + axis] - X) / X;
      ++lateral_count;
    }
  }
  const double lateral_strain = lateral_sum / lateral_count;
  EXPECT_NEAR(lateral_strain / strain, -material.poisson_ratio, 0.01 * material.poisson_ratio);

  // Axial stress from the reaction on the pulled face.
  const auto reactions = sim.reactions();
  ASSERT_EQ(reactions.size(), 4u);
  EXPECT_EQ(reactions[3].name, "displacement[0]");
  const double stress = reactions[3].force.x() / (W * W);
  EXPECT_NEAR(stress, material.youngs_modulus * strain, 0.01 * material.youngs_modulus * strain);
  // The opposite face carries the opposite force (all reactions balance without loads).
  Vector3d total = Vector3d::Zero();
  for (const GroupReaction& r : reactions)
    total += r.force;
  EXPECT_LT(total.norm(), 1e-6 * std::abs(reactions[3].force.x()));
}

INSTANTIATE_TEST_SUITE_P(SimPhysics, UniaxialTension, ::testing::ValuesIn(testing::kAllModels),
                         [](const auto& info) { return to_string(info.param); });

}  // namespace
}  // namespace strata
