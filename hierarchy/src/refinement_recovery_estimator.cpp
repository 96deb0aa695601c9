#include "strata/hierarchy/refinement_recovery_estimator.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/fem/green_strain.hpp"
#include "strata/core/fem/isotropic_stress.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

namespace {

/// Tets per parallel task.
constexpr Index kTetChunk = 2048;

/// The share of the budget a merge's predicted local term may take: the prediction holds the
/// parent's neighbours as they are, and merges side by side raise each other's recovered
/// strains (a block on the ground whose 207 merges, each predicted within 0.8 τ, took the local
/// term from 0.48 % to 0.95 %).
constexpr double kMergeLocalMargin = 0.5;

/// The cube of the edge of a regular tet per its volume, 6√2: h = (6√2 V)^⅓.
constexpr double kRegularTetEdgeCubed = 8.48528137423857;

/// 2ψ(e) = 2μ e:e + λ tr(e)² for a symmetric tensor in Voigt form [xx yy zz xy yz xz].
double twice_energy_density(const Vector6d& e, const LameParameters& lame) {
  const double trace = e[0] + e[1] + e[2];
  const double contraction = e.head<3>().squaredNorm() + 2.0 * e.tail<3>().squaredNorm();
  return 2.0 * lame.mu * contraction + lame.lambda * trace * trace;
}

/// The share of a level-ℓ tet's energy-norm error that refinement to the finest level L removes,
/// in the measure of displacements: (1 − 2^−(L−ℓ)) · (h_ℓ / h_0)^½ (see the header).
double displacement_share_removed(int depth, int level) {
  return (1.0 - std::ldexp(1.0, -(depth - level))) * std::pow(2.0, -0.5 * level);
}

/// The share of a level-ℓ tet's squared energy-norm error that lies between it and the finest
/// level L, 1 − 4^−(L−ℓ) (Galerkin orthogonality; the error energy falls by 4 per level).
double energy_share_removed(int depth, int level) {
  return 1.0 - std::ldexp(1.0, -2 * (depth - level));
}

/// The share of the tolerance the tets' terms of z are marked against: τ_z = (τ² z² / c)^⅓ =
/// z (τ/e)^⅔, which is z when e = τ. A heuristic, not a derivation: it would be exact if c fell
/// as z² under refinement; with an error energy falling by 4 per level (c by 4, z² by 8) it
/// would be z (τ/e)^{6/7}, which marks more per pass. The smaller exponent marks less and lets
/// the next pass's estimate decide; the state's own c, τ² / c, marked far too much (README,
/// "Error control"). Plastic: τ; c = 0 (every tet at the finest level): ∞.
double upper_tolerance(const RecoveryEstimate& estimate, double tolerance) {
  if (estimate.upper_only) return tolerance;
  if (estimate.load_work_error <= 0.0) return std::numeric_limits<double>::infinity();
  return std::cbrt(tolerance * tolerance * estimate.upper_error * estimate.upper_error /
                   estimate.load_work_error);
}

/// Eight sibling flat tets: their rest volumes, total volume and volume-weighted mean Green
/// strain Ē (near the strain of the parent's one linear field where the children turn alike,
/// merged_strain).
struct Siblings {
  std::array<double, 8> volume{};
  double total = 0.0;
  Vector6d mean = Vector6d::Zero();
};

Siblings siblings(const CutState& state, const std::array<int, 8>& children) {
  const TetMesh& mesh = state.flat.mesh;
  const auto& strain = state.fields.green_strain;
  Siblings result;
  for (int k = 0; k < 8; ++k) {
    const auto corner = [&](int i) {
      return Vector3d(mesh.vertices.row(mesh.tets(children[k], i)).transpose());
    };
    result.volume[k] = std::abs(tet_signed_volume(corner(0), corner(1), corner(2), corner(3)));
    result.mean += result.volume[k] * strain.row(children[k]).transpose();
    result.total += result.volume[k];
  }
  if (result.total > 0.0) result.mean /= result.total;
  return result;
}

/// Σ_k 2 V_k ψ(E_k − Ē) over the eight children (flat tets): the strain energy of the detail a
/// merge into the parent averages away [J].
double merge_loss(const CutState& state, const std::array<int, 8>& children) {
  const Siblings sibling = siblings(state, children);
  const auto& strain = state.fields.green_strain;
  const LameParameters lame = state.material.lame();
  double loss = 0.0;
  for (int k = 0; k < 8; ++k)
    loss += sibling.volume[k] *
            twice_energy_density(strain.row(children[k]).transpose() - sibling.mean, lame);
  return loss;
}

/// The share of a level-ℓ tet's local term that refinement to the finest level L removes,
/// 1 − 2^−(L−ℓ).
double local_share_removed(int depth, int level) {
  return 1.0 - std::ldexp(1.0, -(depth - level));
}

/// e:e of a symmetric tensor in Voigt form [xx yy zz xy yz xz].
double frobenius_sq(const Vector6d& e) {
  return e.head<3>().squaredNorm() + 2.0 * e.tail<3>().squaredNorm();
}

/// |e| = √(e:e).
double frobenius(const Vector6d& e) {
  return std::sqrt(frobenius_sq(e));
}

/// The Green strain (Voigt [xx yy zz xy yz xz]) of `parent` once merged: of the linear field
/// through its corners' current positions, which are vertices of the flat cut (its corner
/// children's). Where the children turn against each other this is not their mean strain: the
/// mean of rotations is a shrink.
Vector6d merged_strain(const CutState& state, NodeId parent) {
  const std::array<int, 4> corners = state.tree.tet_vertices(parent);
  Matrix3d rest, deformed;
  std::array<Vector3d, 4> X, x;
  for (int i = 0; i < 4; ++i) {
    const int v = state.flat.mesh_vertices[corners[i]];
    STRATA_VERIFY(v >= 0, "merged_strain: a corner of a merge is not a vertex of the cut");
    X[i] = state.flat.mesh.vertices.row(v).transpose();
    x[i] = state.positions.segment<3>(3 * Index(v));
  }
  for (int j = 0; j < 3; ++j) {
    rest.col(j) = X[j + 1] - X[0];
    deformed.col(j) = x[j + 1] - x[0];
  }
  return to_voigt(green_strain(deformed * rest.inverse()));
}

/// The predicted local term δ of `parent` (level `parent_level`), the parent of eight sibling flat
/// tets, once merged [m]: the parent's share times its size (the edge of a regular tet of their
/// total volume, twice theirs) times the larger of two strain errors. One is the parent's own
/// strain (merged_strain) against the recovered strains at its corners now, which is what its
/// term reads after the merge as far as its neighbours' strains stay (children on the finest
/// level count no term of their own, however far their neighbours' strains are from theirs: a
/// merge inside a clamped region beside a strained one). The other is the largest strain error
/// of a child not on the finest level, plus the largest deviation of a child's strain from their
/// mean, which the parent's one linear field averages away, plus the difference between the
/// parent's strain and that mean.
double merged_local_error(const CutState& state, const RecoveryEstimate& estimate, NodeId parent,
                          const std::array<int, 8>& children, int depth, int parent_level) {
  const Siblings sibling = siblings(state, children);
  if (!(sibling.total > 0.0)) return 0.0;
  const Vector6d parent_strain = merged_strain(state, parent);
  double corner_difference = 0.0;
  for (const int v : state.tree.tet_vertices(parent)) {
    const Index mesh_vertex = state.flat.mesh_vertices[v];
    const Vector6d recovered = estimate.recovered_strain.row(mesh_vertex).head<6>().transpose();
    corner_difference = std::max(corner_difference, frobenius(recovered - parent_strain));
  }
  const auto& strain = state.fields.green_strain;
  // The children's strain errors as their own local terms count them: relative to the finest
  // level, so nothing on it (the full-resolution run has the same), and the detail each child
  // adds to the parent's error on top.
  const double child_share = local_share_removed(depth, parent_level + 1);
  double child_difference = 0.0, detail = 0.0;
  for (int k = 0; k < 8; ++k) {
    const double h = std::cbrt(kRegularTetEdgeCubed * sibling.volume[k]);
    if (child_share > 0.0 && h > 0.0)
      child_difference =
          std::max(child_difference, estimate.element_local_error[children[k]] / (child_share * h));
    detail = std::max(detail, frobenius(strain.row(children[k]).transpose() - sibling.mean));
  }
  const double own = frobenius(parent_strain - sibling.mean);
  return local_share_removed(depth, parent_level) *
         std::cbrt(kRegularTetEdgeCubed * sibling.total) *
         std::max(corner_difference, child_difference + detail + own);
}

/// What the terms of the estimate read, per tet and per vertex.
struct TermArrays {
  const int* corners[4];    ///< the columns of the tets' vertex indices
  const double* strain;     ///< #T × 6 Green strains, column-major
  Index num_tets;           ///< the strain column stride
  const double* recovered;  ///< #V rows of 7: the recovered strain, then the volume
  LameParameters lame;
};

/// One tet's sums over its corners i of d_i = E*_i − E_t: Σ 2ψ(d_i) + 2ψ(Σ d_i), max |d_i|², and
/// 2ψ(E_t).
struct TetTerms {
  double error_factor;
  double largest_difference_sq;
  double own_energy;
};

/// Tets per vectorised group of the terms.
constexpr int kTermLanes = 4;
static_assert(kTetChunk % kTermLanes == 0);

/// The terms of tets t … t + N − 1, lane by lane (so the compiler keeps N of each operation side
/// by side): 2ψ(e) = 2μ e:e + λ tr(e)², e:e = Σ e_c² (c < 3) + 2 Σ e_c² (c ≥ 3).
template <int N>
void tet_terms(const TermArrays& a, Index t, TetTerms (&out)[N]) {
  const double two_mu = 2.0 * a.lame.mu, lambda = a.lame.lambda;
  const auto density = [&](const double(&e)[6][N], double(&result)[N], double(&frobenius)[N]) {
    for (int l = 0; l < N; ++l) {
      const double trace = e[0][l] + e[1][l] + e[2][l];
      const double contraction = e[0][l] * e[0][l] + e[1][l] * e[1][l] + e[2][l] * e[2][l] +
                                 2.0 * (e[3][l] * e[3][l] + e[4][l] * e[4][l] + e[5][l] * e[5][l]);
      frobenius[l] = contraction;
      result[l] = two_mu * contraction + lambda * trace * trace;
    }
  };
  double own[6][N], sum[6][N] = {}, d[6][N];
  for (int c = 0; c < 6; ++c)
    for (int l = 0; l < N; ++l)
      own[c][l] = a.strain[c * a.num_tets + t + l];
  double vertex_terms[N] = {}, largest[N] = {}, term[N], frobenius[N];
  for (int k = 0; k < 4; ++k) {
    for (int l = 0; l < N; ++l) {
      const double* row = a.recovered + 7 * Index(a.corners[k][t + l]);
      for (int c = 0; c < 6; ++c)
        d[c][l] = row[c] - own[c][l];
    }
    density(d, term, frobenius);
    for (int l = 0; l < N; ++l) {
      vertex_terms[l] += term[l];
      largest[l] = std::max(largest[l], frobenius[l]);
    }
    for (int c = 0; c < 6; ++c)
      for (int l = 0; l < N; ++l)
        sum[c][l] += d[c][l];
  }
  double sum_term[N], own_term[N];
  density(sum, sum_term, frobenius);
  density(own, own_term, frobenius);
  for (int l = 0; l < N; ++l)
    out[l] = {vertex_terms[l] + sum_term[l], largest[l], own_term[l]};
}

}  // namespace

RecoveryGeometry recovery_geometry(const TetMesh& mesh) {
  RecoveryGeometry geometry;
  geometry.volume = tet_rest_volumes(mesh);
  const Index num_tets = mesh.tets.rows();
  geometry.size.resize(num_tets);
  tbb::parallel_for(Index(0), num_tets, kTetChunk, [&](Index begin) {
    const Index end = std::min(begin + kTetChunk, num_tets);
    for (Index t = begin; t < end; ++t)
      geometry.size[t] = std::cbrt(kRegularTetEdgeCubed * std::abs(geometry.volume[t]));
  });
  geometry.incident = vertex_tets(mesh.tets, mesh.vertices.rows());
  return geometry;
}

RecoveryEstimate recovery_error_estimate(const CutState& state) {
  const TetMesh& mesh = state.flat.mesh;
  const Index num_tets = mesh.tets.rows();
  const Index num_vertices = mesh.vertices.rows();
  const LameParameters lame = state.material.lame();
  STRATA_VERIFY(static_cast<Index>(state.flat.tet_levels.size()) == num_tets,
                "recovery_error_estimate: the flat mesh has no levels for its tets");
  RecoveryGeometry computed_geometry;
  if (state.recovery_geometry == nullptr) computed_geometry = recovery_geometry(mesh);
  const RecoveryGeometry& geometry =
      state.recovery_geometry != nullptr ? *state.recovery_geometry : computed_geometry;
  STRATA_VERIFY(geometry.volume.size() == num_tets && geometry.incident.size() == num_vertices,
                "recovery_error_estimate: the rest geometry is not of this cut");
  const VectorXd& volume = geometry.volume;
  const auto& strain = state.fields.green_strain;
  STRATA_VERIFY(strain.rows() == num_tets,
                "recovery_error_estimate: the strains are not of this cut's tets");

  RecoveryEstimate estimate;
  // Per vertex, row by row: the volume-weighted sum of its tets' strains (tets ascending), then
  // their volume; the sum becomes the recovered (mean) strain.
  auto& recovered = estimate.recovered_strain;
  recovered.resize(num_vertices, 7);
  tbb::parallel_for(Index(0), num_vertices, kTetChunk, [&](Index begin) {
    const Index end = std::min(begin + kTetChunk, num_vertices);
    for (Index v = begin; v < end; ++v) {
      double sums[7] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
      for (const int t : geometry.incident[v]) {
        for (int c = 0; c < 6; ++c)
          sums[c] += volume[t] * strain(t, c);
        sums[6] += volume[t];
      }
      if (sums[6] > 0.0)
        for (int c = 0; c < 6; ++c)
          sums[c] /= sums[6];
      for (int c = 0; c < 7; ++c)
        recovered(v, c) = sums[c];
    }
  });

  estimate.element_error_sq.resize(num_tets);
  estimate.element_raw_error_sq.resize(num_tets);
  const int depth = state.tree.max_level();
  std::vector<double> removed(static_cast<std::size_t>(depth) + 1), c_share(removed.size()),
      local_share(removed.size());
  for (int level = 0; level <= depth; ++level) {
    removed[level] = displacement_share_removed(depth, level);
    c_share[level] = energy_share_removed(depth, level);
    local_share[level] = local_share_removed(depth, level);
  }
  // The tets' terms in parallel, their sums in tet order (the same at any thread count).
  VectorXd load_work_terms(num_tets), energy_terms(num_tets);
  estimate.element_local_error.resize(num_tets);
  const TermArrays arrays{{mesh.tets.col(0).data(), mesh.tets.col(1).data(),
                           mesh.tets.col(2).data(), mesh.tets.col(3).data()},
                          strain.data(),
                          num_tets,
                          recovered.data(),
                          lame};
  tbb::parallel_for(Index(0), num_tets, kTetChunk, [&](Index begin) {
    const Index end = std::min(begin + kTetChunk, num_tets);
    // Four tets at a time (kTetChunk is a multiple of 4), the last ones of the cut one by one: the
    // same arithmetic either way.
    const auto store = [&](Index t, const TetTerms& terms) {
      const double error_sq = volume[t] / 20.0 * terms.error_factor;
      const int level = state.flat.tet_levels[t];
      estimate.element_error_sq[t] = error_sq * removed[level] * removed[level];
      estimate.element_raw_error_sq[t] = error_sq;
      load_work_terms[t] = error_sq * c_share[level];
      estimate.element_local_error[t] =
          local_share[level] * geometry.size[t] * std::sqrt(terms.largest_difference_sq);
      energy_terms[t] = volume[t] * terms.own_energy;
    };
    Index t = begin;
    for (; t + kTermLanes <= end; t += kTermLanes) {
      TetTerms terms[kTermLanes];
      tet_terms<kTermLanes>(arrays, t, terms);
      for (int l = 0; l < kTermLanes; ++l)
        store(t + l, terms[l]);
    }
    for (; t < end; ++t) {
      TetTerms terms[1];
      tet_terms<1>(arrays, t, terms);
      store(t, terms[0]);
    }
  });
  double total = 0.0, raw_total = 0.0, load_work_total = 0.0;
  for (Index t = 0; t < num_tets; ++t) {
    raw_total += estimate.element_raw_error_sq[t];
    load_work_total += load_work_terms[t];
    total += estimate.element_error_sq[t];
    estimate.solution_energy_sq += energy_terms[t];
  }
  estimate.reference_energy_sq = std::max(estimate.solution_energy_sq, state.solution_energy_scale);
  if (estimate.reference_energy_sq > 0.0) {
    estimate.upper_error =
        kDisplacementPerEnergyError * std::sqrt(total / estimate.reference_energy_sq);
    estimate.load_work_error = load_work_total / estimate.reference_energy_sq;
    estimate.upper_only = state.material.plasticity.has_value();
    estimate.relative_error = estimate.upper_only
                                  ? estimate.upper_error
                                  : std::sqrt(estimate.upper_error * estimate.load_work_error);
    estimate.relative_energy_error = std::sqrt(raw_total / estimate.reference_energy_sq);
  }
  estimate.recovery_error = estimate.relative_error;
  // The local estimate, relative to the largest displacement.
  double largest_displacement = 0.0;
  for (Index v = 0; v < num_vertices; ++v)
    largest_displacement = std::max(
        largest_displacement,
        (state.positions.segment<3>(3 * v) - mesh.vertices.row(v).transpose()).squaredNorm());
  estimate.reference_displacement =
      std::max(std::sqrt(largest_displacement), state.solution_displacement_scale);
  if (estimate.reference_displacement > 0.0 && num_tets > 0) {
    estimate.local_error =
        estimate.element_local_error.maxCoeff() / estimate.reference_displacement;
    estimate.relative_error = std::max(estimate.relative_error, estimate.local_error);
  }
  return estimate;
}

RecoveryIndicator::RecoveryIndicator(double tolerance) : m_tolerance(tolerance) {
  if (!(tolerance > 0.0 && tolerance < 1.0))
    throw InputError("hierarchy.tolerance: must be in (0, 1)");
}

void RecoveryIndicator::evaluate(const CutState& state, VectorXd& eta) const {
  RecoveryEstimate computed;
  if (state.recovery_estimate == nullptr) computed = recovery_error_estimate(state);
  const RecoveryEstimate& estimate =
      state.recovery_estimate != nullptr ? *state.recovery_estimate : computed;
  const Index n = estimate.element_error_sq.size();
  eta.setZero(n);
  if (estimate.reference_energy_sq <= 0.0 || n == 0) return;
  const double tolerance = m_tolerance / state.tolerance_scale;
  const double energy_tolerance =
      upper_tolerance(estimate, tolerance) / kDisplacementPerEnergyError;
  const double share = energy_tolerance * energy_tolerance * estimate.reference_energy_sq / n;
  eta = (estimate.element_error_sq / share).cwiseSqrt();
  if (estimate.reference_displacement > 0.0)
    eta =
        eta.cwiseMax(estimate.element_local_error / (tolerance * estimate.reference_displacement));
}

double RecoveryIndicator::merge_indicator(const CutState& state, const std::array<int, 8>& children,
                                          int parent_level) const {
  RecoveryEstimate computed;
  if (state.recovery_estimate == nullptr) computed = recovery_error_estimate(state);
  const RecoveryEstimate& estimate =
      state.recovery_estimate != nullptr ? *state.recovery_estimate : computed;
  const Index n = estimate.element_error_sq.size();
  if (estimate.reference_energy_sq <= 0.0 || n == 0) return 0.0;
  const double loss = merge_loss(state, children);
  const int depth = state.tree.max_level();
  const double removed = displacement_share_removed(depth, parent_level);
  // A merge raises c, which τ_z (from this state's c) does not see; on the finest level c = 0
  // and τ_z = ∞. The merge is judged against the smaller of τ_z and τ, never more loosely than
  // the upper estimate alone would allow.
  const double tolerance = m_tolerance / state.tolerance_scale;
  const double merge_tolerance = std::min(tolerance, upper_tolerance(estimate, tolerance));
  const double energy_tolerance = merge_tolerance / kDisplacementPerEnergyError;
  const double share = energy_tolerance * energy_tolerance * estimate.reference_energy_sq / n;
  return std::sqrt(loss * removed * removed / share);
}

BudgetedMerges merges_within_budget(const CutState& state, const RecoveryEstimate& estimate,
                                    const std::vector<NodeId>& parents, double budget) {
  BudgetedMerges result;
  result.predicted_error = estimate.recovery_error;
  const double reference = estimate.reference_energy_sq;
  if (!(reference > 0.0) || parents.empty()) {
    result.kept = parents;
    std::sort(result.kept.begin(), result.kept.end());
    return result;
  }
  const TetTree& tree = state.tree;
  const FlatTreeMesh& flat = state.flat;
  const Index num_tets = flat.mesh.tets.rows();
  STRATA_VERIFY(estimate.element_raw_error_sq.size() == num_tets &&
                    estimate.recovered_strain.rows() == flat.mesh.vertices.rows(),
                "merges_within_budget: the estimate is not of this state");
  std::vector<int> node_tet(static_cast<std::size_t>(tree.pool_size()), -1);
  for (Index t = 0; t < num_tets; ++t)
    node_tet[flat.tet_nodes[t]] = static_cast<int>(t);
  // A merge never lowers the local term either: while it exceeds the budget nothing merges.
  if (estimate.local_error > budget) return result;
  const bool upper_only = estimate.upper_only;
  const double reference_displacement = estimate.reference_displacement;
  const double z_scale = kDisplacementPerEnergyError * kDisplacementPerEnergyError / reference;
  double z_sq = estimate.upper_error * estimate.upper_error / z_scale;  // Σ terms of z² [J]
  double c = estimate.load_work_error * reference;                      // Σ terms of c [J]
  // The estimate after the merges kept so far plus rises (dz, dc).
  const auto predicted = [&](double dz, double dc) {
    const double z = std::sqrt(std::max(0.0, (z_sq + dz) * z_scale));
    return upper_only ? z : std::sqrt(z * std::max(0.0, (c + dc) / reference));
  };
  const int depth = tree.max_level();
  const auto z_share = [&](int level) {
    const double removed = displacement_share_removed(depth, level);
    return removed * removed;
  };
  struct Merge {
    NodeId parent;
    double dz;     // rise of z² ‖u‖² [J]
    double dc;     // rise of c ‖u‖² [J]
    double alone;  // the estimate after this merge alone
  };
  std::vector<Merge> merges;
  merges.reserve(parents.size());
  for (const NodeId parent : parents) {
    std::array<int, 8> children{};
    double children_sq = 0.0;
    for (int k = 0; k < 8; ++k) {
      children[k] = node_tet[tree.child(parent, k)];
      STRATA_VERIFY(children[k] >= 0, "merges_within_budget: a child of a merge is not active");
      children_sq += estimate.element_raw_error_sq[children[k]];
    }
    const int level = tree.level(parent);
    // The local term of the parent: twice its children's size, across their strain error plus
    // the detail the merge averages away. A merge that would put it above its share of the
    // budget is not made (whatever the energy-norm estimate allows): the merged node may not be
    // refined again for a while (min_steps_between_changes).
    if (reference_displacement > 0.0 &&
        merged_local_error(state, estimate, parent, children, depth, level) >
            kMergeLocalMargin * budget * reference_displacement)
      continue;
    const double parent_sq = std::max(4.0 * children_sq, children_sq + merge_loss(state, children));
    const double dz = parent_sq * z_share(level) - children_sq * z_share(level + 1);
    const double dc = parent_sq * energy_share_removed(depth, level) -
                      children_sq * energy_share_removed(depth, level + 1);
    merges.push_back({parent, dz, dc, predicted(dz, dc)});
  }
  // Cheapest first; every merge that still fits is kept: one that does not may leave room for a
  // later one that raises the other bracket less.
  std::sort(merges.begin(), merges.end(), [](const Merge& a, const Merge& b) {
    return a.alone != b.alone ? a.alone < b.alone : a.parent < b.parent;
  });
  for (const Merge& merge : merges) {
    const double after = predicted(merge.dz, merge.dc);
    if (after > budget) continue;
    z_sq += merge.dz;
    c += merge.dc;
    result.kept.push_back(merge.parent);
    result.predicted_error = after;
  }
  std::sort(result.kept.begin(), result.kept.end());
  return result;
}

}  // namespace strata
