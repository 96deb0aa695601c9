#pragma once
/// \file bench_fixture.hpp
/// Shared set-up of the benchmarks: box meshes of ~50k and ~400k tets, a smooth deformed state and
/// a cache holding the most recently built ElasticModel (building the stiffness pattern of the
/// large mesh takes longer than one measurement).
#include <sys/resource.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <strata/core/fem/elastic_model.hpp>
#include <strata/core/fem/material.hpp>
#include <strata/core/fem/material_registry.hpp>
#include <strata/core/mesh/tet_mesh.hpp>

namespace strata::bench {

/// A benchmark mesh: `cells` box cells, 6 tets each, over [0, cells·h]³ with h = 1/cells[0] m.
struct MeshSize {
  std::array<int, 3> cells;
  long long num_tets() const { return 6LL * cells[0] * cells[1] * cells[2]; }
};

/// 20×20×21 cells = 50,400 tets; 40×40×42 cells = 403,200 tets.
inline const std::vector<MeshSize>& mesh_sizes() {
  static const std::vector<MeshSize> sizes = {{{20, 20, 21}}, {{40, 40, 42}}};
  return sizes;
}

inline const std::vector<MaterialModel>& material_models() {
  static const std::vector<MaterialModel> models = [] {
    std::vector<MaterialModel> all;
    for (const MaterialModelTraits& traits : material_registry())
      all.push_back(traits.model);
    return all;
  }();
  return models;
}

inline const std::vector<int>& thread_counts() {
  static const std::vector<int> threads = {1, 2};
  return threads;
}

/// "<prefix>/tets:<#T>/threads:<n>".
/// User and system CPU seconds of the whole process so far (getrusage): differences around a
/// timed loop give its system-time share.
struct CpuSeconds {
  double user = 0.0;
  double system = 0.0;
};
inline CpuSeconds process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  return {seconds(usage.ru_utime), seconds(usage.ru_stime)};
}
/// System over user CPU time between two readings (0 when no user time passed).
inline double system_share(const CpuSeconds& start, const CpuSeconds& end) {
  const double user = end.user - start.user;
  return user > 0.0 ? (end.system - start.system) / user : 0.0;
}

inline std::string benchmark_name(const std::string& prefix, const MeshSize& size, int threads) {
  return prefix + "/tets:" + std::to_string(size.num_tets()) +
         "/threads:" + std::to_string(threads);
}

/// Box mesh of the given size with cubic cells of edge 1/cells[0] m.
TetMesh benchmark_mesh(const MeshSize& size);

/// Rest positions plus a smooth displacement of ~1 % of the box size (3·#V).
VectorXd deformed_positions(const TetMesh& mesh);

/// A rubber-like material: E = 1 MPa, ν = 0.3, ρ = 1000 kg/m³.
Material benchmark_material(MaterialModel model);

/// The mesh and elastic model for (size, model); the last one built is kept and reused.
struct ModelCase {
  TetMesh mesh;
  std::unique_ptr<ElasticModel> model;
  VectorXd deformed;
};
const ModelCase& model_case(const MeshSize& size, MaterialModel model);

}  // namespace strata::bench
