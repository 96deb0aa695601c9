#include "bench_fixture.hpp"

#include <cmath>
#include <numbers>

namespace strata::bench {

TetMesh benchmark_mesh(const MeshSize& size) {
  const double h = 1.0 / size.cells[0];
  const Vector3d max(h * size.cells[0], h * size.cells[1], h * size.cells[2]);
  return box_tet_mesh(Vector3d::Zero(), max, size.cells);
}

VectorXd deformed_positions(const TetMesh& mesh) {
  VectorXd x = flatten(mesh.vertices);
  const double k = 2.0 * std::numbers::pi;
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d X = mesh.vertices.row(v).transpose();
    x[3 * v + 0] += 0.01 * std::sin(k * X.y()) * X.z();
    x[3 * v + 1] += 0.01 * std::cos(k * X.z()) * X.x();
    x[3 * v + 2] += 0.01 * std::sin(k * X.x()) * X.y();
  }
  return x;
}

Material benchmark_material(MaterialModel model) {
  Material material;
  material.model = model;
  material.youngs_modulus = 1e6;
  material.poisson_ratio = 0.3;
  material.density = 1000.0;
  return material;
}

const ModelCase& model_case(const MeshSize& size, MaterialModel model) {
  static ModelCase cached;
  static std::array<int, 3> cached_cells = {0, 0, 0};
  static MaterialModel cached_model = MaterialModel::stvk;
  if (cached.model && cached_cells == size.cells && cached_model == model) return cached;
  cached.model.reset();
  cached.mesh = benchmark_mesh(size);
  cached.model = std::make_unique<ElasticModel>(cached.mesh.vertices, cached.mesh.tets,
                                                benchmark_material(model));
  cached.deformed = deformed_positions(cached.mesh);
  cached_cells = size.cells;
  cached_model = model;
  return cached;
}

}  // namespace strata::bench
