// The elastic model of an adaptive cut: a 1 × 1 × 1 m box of 8 × 8 × 8 coarse cells (3,072
// roots, 3 levels) refined to level 3 where a tet comes within 0.25 m of the top face's centre,
// and graded outwards (level 2 within 0.5 m, level 1 within 0.75 m): levels 0–3 side by side, with
// hanging vertices where they meet, as a local load leaves a cut. Neo-Hookean, E = 1 MPa, ν = 0.45.
//   - cut_stiffness/flatten/threads:<n>: what a cut change spends on the flattened cut (mesh,
//     hanging-vertex constraints) and its nested spaces for the multigrid;
//   - cut_stiffness/build/threads:<n>: what a cut change spends on the elastic model, the mesh
//     model (rest data, tet partition) and the reduced one (K_q's pattern and assembly plan) of
//     the flattened cut;
//   - cut_stiffness/assemble/<raw|psd>/threads:<n>: one K_q = Pᵀ K P at a deformed state, as a
//     Newton iteration assembles it;
//   - cut_stiffness/estimate/<strains|fields>/threads:<n>: the test an adaptive run makes of every
//     step's result at a deformed state, the recovery error estimate
//     (refinement_recovery_estimator.hpp) from the tets' Green strains alone (what a step whose
//     estimate is within the tolerance computes) or from all their fields (strains and stresses,
//     what a decision that goes on to the controller needs).
// Counters: tets, DOFs (3 · free vertices), hanging vertices, K_q's non-zeros.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <string>

#include <strata/core/common/parallel.hpp>
#include <strata/core/fem/elastic_model.hpp>
#include <strata/core/sim/embedded_model.hpp>
#include <strata/hierarchy/active_cut.hpp>
#include <strata/hierarchy/cut_levels.hpp>
#include <strata/hierarchy/cut_state.hpp>
#include <strata/hierarchy/hanging_constraints.hpp>
#include <strata/hierarchy/refinement_recovery_estimator.hpp>

namespace strata::bench {
namespace {

struct GradedCut {
  std::unique_ptr<TetTree> tree;
  std::unique_ptr<ActiveCut> cut_nodes;
  std::unique_ptr<ConstrainedCut> cut;
  Material material;
};

const GradedCut& graded_cut() {
  static const GradedCut graded = [] {
    GradedCut g;
    g.tree =
        std::make_unique<TetTree>(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {8, 8, 8}), 3);
    ActiveCut cut = ActiveCut::uniform(*g.tree, 0);
    const Vector3d load(0.5, 0.5, 1.0);
    for (int level = 0; level < 3; ++level)
      for (const NodeId n : cut.sorted_nodes()) {
        if (g.tree->level(n) != level) continue;
        const auto corners = g.tree->tet_positions(n);
        double nearest = 1e300;
        for (int k = 0; k < 4; ++k)
          nearest = std::min(nearest, (corners.col(k) - load).norm());
        if (nearest < 0.75 - 0.25 * level) cut.refine(n);
      }
    g.cut = std::make_unique<ConstrainedCut>(flatten_cut(cut));
    g.cut_nodes = std::make_unique<ActiveCut>(std::move(cut));
    g.material.model = MaterialModel::neohookean;
    g.material.youngs_modulus = 1e6;
    g.material.poisson_ratio = 0.45;
    g.material.density = 1000.0;
    return g;
  }();
  return graded;
}

/// The mesh model of the graded cut and the reduced one on its free vertices (which points to the
/// mesh model: not copied).
struct CutModels {
  explicit CutModels(const GradedCut& g)
      : model(g.cut->flat.mesh.vertices, g.cut->flat.mesh.tets, g.material),
        embedded(model, g.cut->constraints.matrix(), g.cut->constraints.free_vertices()) {}
  CutModels(const CutModels&) = delete;
  CutModels& operator=(const CutModels&) = delete;
  ElasticModel model;
  EmbeddedElasticModel embedded;
};

void set_cut_counters(benchmark::State& state, const GradedCut& g,
                      const EmbeddedElasticModel& embedded) {
  state.counters["tets"] = double(g.cut->flat.mesh.tets.rows());
  state.counters["dofs"] = double(embedded.num_dofs());
  state.counters["hanging"] = double(g.cut->constraints.num_hanging());
  state.counters["nonzeros"] = double(embedded.stiffness_pattern().nonZeros());
}

void flatten_benchmark(benchmark::State& state, int threads) {
  const ThreadLimit limit(threads);
  const GradedCut& g = graded_cut();
  for (auto _ : state) {
    const ConstrainedCut cut = flatten_cut(*g.cut_nodes);
    const NestedSpaces spaces = cut_nested_spaces(*g.tree, cut);
    benchmark::DoNotOptimize(spaces.num_levels());
  }
  const CutModels models(g);
  set_cut_counters(state, g, models.embedded);
}

void build_benchmark(benchmark::State& state, int threads) {
  const ThreadLimit limit(threads);
  const GradedCut& g = graded_cut();
  for (auto _ : state) {
    const CutModels models(g);
    benchmark::DoNotOptimize(models.embedded.stiffness_pattern().nonZeros());
  }
  const CutModels models(g);
  set_cut_counters(state, g, models.embedded);
}

/// A smooth bend of the free vertices: every element strained, none inverted.
VectorXd bent_state(const EmbeddedElasticModel& embedded) {
  VectorXd q = embedded.rest_positions();
  for (Index i = 0; i < embedded.num_dof_vertices(); ++i) {
    const double x = q[3 * i];
    q[3 * i + 2] += 0.05 * x * x;
    q[3 * i + 1] *= 1.0 + 0.02 * q[3 * i + 2];
  }
  return q;
}

void assemble_benchmark(benchmark::State& state, bool project_psd, int threads) {
  const ThreadLimit limit(threads);
  const GradedCut& g = graded_cut();
  const CutModels models(g);
  const ElasticModel& model = models.model;
  const EmbeddedElasticModel& embedded = models.embedded;
  const VectorXd q = bent_state(embedded);
  SparseMatrixd K;
  embedded.stiffness(q, K, project_psd);  // sets the pattern, outside the timing
  for (auto _ : state) {
    embedded.stiffness(q, K, project_psd);
    benchmark::DoNotOptimize(K.valuePtr());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * model.num_tets());
  set_cut_counters(state, g, embedded);
}

void estimate_benchmark(benchmark::State& state, bool strains_only, int threads) {
  const ThreadLimit limit(threads);
  const GradedCut& g = graded_cut();
  const CutModels models(g);
  const ElasticModel& model = models.model;
  const EmbeddedElasticModel& embedded = models.embedded;
  const TetMesh& mesh = g.cut->flat.mesh;
  const VectorXd x = embedded.expand(bent_state(embedded));
  const VectorXd loads = VectorXd::Zero(x.size());
  const VectorXd mass = VectorXd::Zero(mesh.vertices.rows());
  double error = 0.0;
  for (auto _ : state) {
    TetFields fields;
    if (strains_only) {
      fields.green_strain = model.green_strains(x);
    } else {
      fields = model.tet_fields(x);
    }
    const CutState cut_state{*g.tree, g.cut->flat, x, fields, loads, mass, g.material};
    error = recovery_error_estimate(cut_state).relative_error;
    benchmark::DoNotOptimize(error);
  }
  state.SetItemsProcessed(state.iterations() * model.num_tets());
  state.counters["estimate"] = error;
  set_cut_counters(state, g, embedded);
}

const bool registered = [] {
  for (int threads : {1, 2}) {
    const std::string suffix = "/threads:" + std::to_string(threads);
    benchmark::RegisterBenchmark(("cut_stiffness/flatten" + suffix).c_str(), flatten_benchmark,
                                 threads)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("cut_stiffness/build" + suffix).c_str(), build_benchmark, threads)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    for (bool psd : {false, true})
      benchmark::RegisterBenchmark(
          ("cut_stiffness/assemble/" + std::string(psd ? "psd" : "raw") + suffix).c_str(),
          assemble_benchmark, psd, threads)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    for (bool strains_only : {true, false})
      benchmark::RegisterBenchmark(
          ("cut_stiffness/estimate/" + std::string(strains_only ? "strains" : "fields") + suffix)
              .c_str(),
          estimate_benchmark, strains_only, threads)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
  return true;
}();

}  // namespace
}  // namespace strata::bench
