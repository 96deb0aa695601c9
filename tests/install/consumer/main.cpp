// Uses the installed strata::core: a box mesh, then elastic energy and forces of each material
// model at rest (zero) and under a uniform stretch (StVK compared with the closed form).
#include <cmath>
#include <cstdio>

#include <strata/core/fem/elastic_model.hpp>
#include <strata/core/fem/material.hpp>
#include <strata/core/fem/material_registry.hpp>
#include <strata/core/mesh/tet_mesh.hpp>

namespace {

int failures = 0;

void check(bool ok, const char* what, double value) {
  std::printf("%-44s %-4s %.3e\n", what, ok ? "ok" : "FAIL", value);
  if (!ok) ++failures;
}

}  // namespace

int main() {
  const strata::Vector3d lo(0.0, 0.0, 0.0);
  const strata::Vector3d hi(2.0, 1.0, 0.5);
  const strata::TetMesh mesh = strata::box_tet_mesh(lo, hi, {4, 2, 2});
  check(mesh.tets.rows() == 6 * 4 * 2 * 2, "box mesh: 6 tets per cell", double(mesh.tets.rows()));
  check(mesh.vertices.rows() == 5 * 3 * 3, "box mesh: vertex count", double(mesh.vertices.rows()));
  const double volume = 2.0 * 1.0 * 0.5;
  check(std::abs(strata::mesh_volume(mesh) - volume) < 1e-12, "box mesh: volume",
        strata::mesh_volume(mesh));

  for (const strata::MaterialModelTraits& traits : strata::material_registry()) {
    const strata::MaterialModel model = traits.model;
    strata::Material material;
    material.model = model;
    material.youngs_modulus = 1e6;
    material.poisson_ratio = 0.3;
    const strata::ElasticModel elastic(mesh.vertices, mesh.tets, material);
    const strata::VectorXd rest = strata::flatten(mesh.vertices);
    std::printf("material %s\n", strata::to_string(model).c_str());

    // Energy scale E·V; at rest the energy of StVK and corotated vanishes and every model is
    // stress-free, so forces vanish too (force scale E·h², h = 0.25 m).
    strata::VectorXd forces;
    elastic.forces(rest, forces);
    check(forces.size() == rest.size(), "  forces: 3·#V entries", double(forces.size()));
    check(forces.cwiseAbs().maxCoeff() < 1e-9 * 1e6 * 0.0625, "  forces at rest = 0",
          forces.cwiseAbs().maxCoeff());
    if (model != strata::MaterialModel::neohookean) {
      const double energy = elastic.energy(rest);
      check(std::abs(energy) < 1e-12 * 1e6 * volume, "  energy at rest = 0", energy);
    }

    // Uniform stretch x = diag(1+s, 1, 1) X: for StVK, Green strain E = diag(e, 0, 0) with
    // e = ((1+s)² − 1)/2 and ψ = (μ + λ/2) e², so Ψ = (μ + λ/2) e² V.
    if (model == strata::MaterialModel::stvk) {
      const double s = 0.1;
      strata::MatrixX3d stretched = mesh.vertices;
      stretched.col(0) *= 1.0 + s;
      const double e = 0.5 * ((1.0 + s) * (1.0 + s) - 1.0);
      const strata::LameParameters lame = material.lame();
      const double expected = (lame.mu + 0.5 * lame.lambda) * e * e * volume;
      const double energy = elastic.energy(strata::flatten(stretched));
      check(std::abs(energy - expected) < 1e-10 * expected, "  stretch energy = (mu+lambda/2)e^2 V",
            energy - expected);
    }
  }
  std::printf("%s\n", failures == 0 ? "consumer: all checks passed" : "consumer: FAILED");
  return failures == 0 ? 0 : 1;
}
