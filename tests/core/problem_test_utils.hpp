#pragma once
// A box mesh bound into a Problem (model, lumped masses, gravity, optional clamp at x = 0), shared
// by the tests of the energy terms, Newton and the steppers.
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "strata/core/fem/elastic_model.hpp"
#include "strata/core/fem/lumped_mass.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/embedded_model.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/problem.hpp"
#include "strata/core/sim/region.hpp"

namespace strata::testing {

struct BoxProblem {
  TetMesh mesh;
  Material material;
  std::unique_ptr<ElasticModel> model;
  std::unique_ptr<EmbeddedElasticModel> embedded;
  VectorXd mass;      ///< per DOF [kg]
  VectorXd external;  ///< gravity [N]
  std::vector<DirichletGroup> groups;
  std::vector<char> constrained;
  std::unique_ptr<Problem> problem;

  /// The box [0, size] with `cells`, under `gravity`; clamped on the face x = 0 if `clamped`.
  BoxProblem(const Vector3d& size, const std::array<int, 3>& cells, const Material& m,
             const Vector3d& gravity, bool clamped)
      : mesh(box_tet_mesh(Vector3d::Zero(), size, cells)), material(m) {
    model = std::make_unique<ElasticModel>(mesh.vertices, mesh.tets, material);
    embedded = std::make_unique<EmbeddedElasticModel>(*model);
    const VectorXd vertex_mass = lumped_vertex_mass(model->rest_data().rest_volume, mesh.tets,
                                                    mesh.vertices.rows(), material.density);
    mass = per_dof_mass(vertex_mass);
    external = gravity_forces(vertex_mass, gravity);
    if (clamped) {
      DirichletSpec clamp;
      clamp.name = "fixed[0]";
      clamp.region = PlaneRegion{Vector3d::Zero(), Vector3d::UnitX(), 0.0};
      groups = resolve_dirichlet_groups({clamp}, mesh.vertices, region_tolerance(mesh.vertices));
    }
    constrained = dirichlet_dof_mask(groups, mesh.vertices.rows());
    problem.reset(new Problem{.model = *embedded,
                              .dof_mass = mass,
                              .external_forces = external,
                              .groups = groups,
                              .constrained = constrained,
                              .diagonal = size.norm()});
  }
};

}  // namespace strata::testing
