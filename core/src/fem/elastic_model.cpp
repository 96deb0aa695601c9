#include "strata/core/fem/elastic_model.hpp"

#include <tbb/blocked_range.h>
#include <tbb/collaborative_call_once.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "batched_stiffness_kernels.hpp"
#include "batched_stress_kernels.hpp"
#include "material_models.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/vector_chunks.hpp"
#include "strata/core/fem/deformation_gradient.hpp"
#include "strata/core/fem/green_strain.hpp"
#include "strata/core/fem/hyperelastic.hpp"
#include "strata/core/fem/isotropic_hessian.hpp"
#include "strata/core/fem/isotropic_stress.hpp"
#include "strata/core/fem/stvk.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

namespace {

// Element kernel of one model (material_models.hpp): its first Piola stress and energy density at
// the run's Lamé parameters, inlined in the loops; the model's LaneKernel, if any, comes with it.
template <typename Model>
struct ModelKernel : Model {
  LameParameters lame;
  explicit ModelKernel(const LameParameters& l) : lame(l) {}
  Matrix3d P(const Matrix3d& F) const { return Model::first_piola(F, lame); }
  double psi(const Matrix3d& F) const { return Model::energy_density(F, lame); }
};

template <typename Body>
void dispatch_kernel(MaterialModel model, const LameParameters& lame, Body&& body) {
  detail::visit_material_model(
      model, [&](auto model_type) { body(ModelKernel<decltype(model_type)>(lame)); });
}

inline Matrix3d edge_matrix_at(const double* x, const int* tet) {
  const Eigen::Map<const Vector3d> x0(x + 3 * tet[0]);
  Matrix3d Ds;
  Ds.col(0) = Eigen::Map<const Vector3d>(x + 3 * tet[1]) - x0;
  Ds.col(1) = Eigen::Map<const Vector3d>(x + 3 * tet[2]) - x0;
  Ds.col(2) = Eigen::Map<const Vector3d>(x + 3 * tet[3]) - x0;
  return Ds;
}

void check_size(ConstRef<VectorXd> x, Index num_dofs) {
  if (x.size() != num_dofs)
    throw std::invalid_argument("ElasticModel: position vector has " + std::to_string(x.size()) +
                                " entries, expected " + std::to_string(num_dofs));
}

}  // namespace

ElasticModel::ElasticModel(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX4i> tets,
                           const Material& material)
    : m_num_vertices(rest_positions.rows()),
      m_tets(tets),
      m_material(material),
      m_lame(material.lame()),
      m_rest_positions(flatten(rest_positions)),
      m_pattern_once(std::make_unique<PatternOnce>()) {
  validate_material(material, "material");
  // Independent, side by side: the partition's sort and colouring are serial passes, which the
  // rest data's parallel loop fills in around. A bad tet is reported by the rest data (the
  // partition skips indices out of range).
  tbb::parallel_invoke([&] { m_rest = compute_tet_rest_data(rest_positions, tets); },
                       [&] { m_partition = build_tet_partition(rest_positions, tets); });
  const Index num_tets = tets.rows();
  m_sorted_tets.resize(4 * num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index i) {
    for (int k = 0; k < 4; ++k)
      m_sorted_tets[4 * i + k] = tets(m_partition.order[i], k);
  });
  fill_rest_arrays();
}

void ElasticModel::fill_rest_arrays() {
  const Index num_tets = m_tets.rows();
  m_sorted_Dm_inv.resize(9 * num_tets);
  m_sorted_volume.resize(num_tets);
  m_sorted_Dm_inv_det.resize(num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index i) {
    const int t = m_partition.order[i];
    Eigen::Map<Matrix3d> Dm_inv(&m_sorted_Dm_inv[9 * i]);
    if (m_plastic_inverse.empty())
      Dm_inv = m_rest.Dm_inv[t];
    else
      Dm_inv = m_rest.Dm_inv[t] * m_plastic_inverse[t];
    m_sorted_volume[i] = m_rest.rest_volume[t];
    m_sorted_Dm_inv_det[i] = Dm_inv.determinant();
  });
  // Rest data regrouped for the vectorised kernels, one contiguous block per lane group g: entry
  // (j, c) of Dm⁻¹ of its kLanes tets at [g · kLaneRest + (3c + j) · kLanes + lane], then the rest
  // volumes at [g · kLaneRest + 9 · kLanes + lane].
  static_assert(kLaneRest == 10 * detail::kLanes);
  const Index num_groups = (num_tets + detail::kLanes - 1) / detail::kLanes;
  m_lane_rest.assign(kLaneRest * num_groups, 0.0);
  tbb::parallel_for(Index(0), num_tets, [&](Index i) {
    double* group = &m_lane_rest[kLaneRest * (i / detail::kLanes)];
    for (int entry = 0; entry < 9; ++entry)
      group[entry * detail::kLanes + i % detail::kLanes] = m_sorted_Dm_inv[9 * i + entry];
    group[9 * detail::kLanes + i % detail::kLanes] = m_sorted_volume[i];
  });
}

void ElasticModel::set_plastic_inverse(const std::vector<Matrix3d>& plastic_inverse) {
  if (!plastic_inverse.empty() && static_cast<Index>(plastic_inverse.size()) != num_tets())
    throw std::invalid_argument("ElasticModel::set_plastic_inverse: expected " +
                                std::to_string(num_tets()) + " matrices");
  m_plastic_inverse = plastic_inverse;
  fill_rest_arrays();
}

namespace {

/// Forces (and energies) of the sorted tets [first, first + kLanes), all lanes at once.
template <bool kWithEnergy, typename LaneKernel>
double lane_group_forces(const LaneKernel& kernel, const double* positions, const int* tets,
                         const double* lane_Dm_inv, const double* volume, double* forces,
                         double* volume_ratio) {
  using detail::kLanes;
  double F[3][3][kLanes];
  detail::lane_deformation_gradient(positions, tets, lane_Dm_inv, F);
  if (volume_ratio != nullptr)
    for (int l = 0; l < kLanes; ++l)
      volume_ratio[l] = F[0][0][l] * (F[1][1][l] * F[2][2][l] - F[1][2][l] * F[2][1][l]) -
                        F[0][1][l] * (F[1][0][l] * F[2][2][l] - F[1][2][l] * F[2][0][l]) +
                        F[0][2][l] * (F[1][0][l] * F[2][1][l] - F[1][1][l] * F[2][0][l]);
  double P[3][3][kLanes], psi[kLanes];
  kernel.template operator()<kWithEnergy>(F, P, psi);
  // H = −V P Dm⁻ᵀ: column j is the force on vertex j + 1.
  double H[3][3][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < kLanes; ++l)
        H[r][j][l] = -volume[l] * (P[r][0][l] * lane_Dm_inv[(0 + j) * kLanes + l] +
                                   P[r][1][l] * lane_Dm_inv[(3 + j) * kLanes + l] +
                                   P[r][2][l] * lane_Dm_inv[(6 + j) * kLanes + l]);
  for (int l = 0; l < kLanes; ++l) {
    const int* tet = tets + 4 * l;
    for (int r = 0; r < 3; ++r) {
      forces[3 * tet[1] + r] += H[r][0][l];
      forces[3 * tet[2] + r] += H[r][1][l];
      forces[3 * tet[3] + r] += H[r][2][l];
      forces[3 * tet[0] + r] -= H[r][0][l] + H[r][1][l] + H[r][2][l];
    }
  }
  double energy = 0.0;
  if constexpr (kWithEnergy)
    for (int l = 0; l < kLanes; ++l)
      energy += volume[l] * psi[l];
  return energy;
}

/// Σ V ψ(F) over one lane group.
template <typename LaneKernel>
double lane_group_energy(const LaneKernel& kernel, const double* positions, const int* tets,
                         const double* lane_Dm_inv, const double* volume) {
  using detail::kLanes;
  double F[3][3][kLanes];
  detail::lane_deformation_gradient(positions, tets, lane_Dm_inv, F);
  double P[3][3][kLanes], psi[kLanes];
  kernel.template operator()<true>(F, P, psi);
  double energy = 0.0;
  for (int l = 0; l < kLanes; ++l)
    energy += volume[l] * psi[l];
  return energy;
}

/// The smallest volume ratio J over tets: the smallest J wins, a NaN before any number, ties to
/// the smaller tet index, so the answer does not depend on the schedule.
struct SmallestVolumeRatio {
  double J = std::numeric_limits<double>::infinity();
  Index tet = -1;
  bool before(const SmallestVolumeRatio& other) const {
    if (tet < 0) return false;
    if (other.tet < 0) return true;
    const bool nan = std::isnan(J), other_nan = std::isnan(other.J);
    if (nan != other_nan) return nan;
    if (!nan && J != other.J) return J < other.J;
    return tet < other.tet;
  }
};

/// Tets ahead of the current lane group whose vertex data is prefetched.
constexpr int kPrefetchTets = 32;

/// Prefetches position and force entries of the kLanes tets `tets`.
inline void prefetch_vertices(const int* tets, const double* positions, const double* forces) {
  for (int k = 0; k < 4 * detail::kLanes; ++k) {
    __builtin_prefetch(positions + 3 * tets[k], 0, 3);
    __builtin_prefetch(forces + 3 * tets[k], 1, 3);
  }
}

}  // namespace

template <typename Kernel>
void ElasticModel::accumulate_forces(const Kernel& kernel, ConstRef<VectorXd> x, VectorXd& f,
                                     double* energy,
                                     std::pair<double, Index>* smallest_volume_ratio) const {
  std::vector<double> chunk_energy(energy ? m_partition.num_chunks() : 0, 0.0);
  const bool ratios = smallest_volume_ratio != nullptr;
  std::vector<SmallestVolumeRatio> chunk_smallest(ratios ? m_partition.num_chunks() : 0);
  const double* positions = x.data();
  double* forces = f.data();
  const auto scalar_tet = [&](int i, int chunk) {
    const int* tet = &m_sorted_tets[4 * i];
    const Eigen::Map<const Matrix3d> Dm_inv(&m_sorted_Dm_inv[9 * i]);
    const Matrix3d F = edge_matrix_at(positions, tet) * Dm_inv;
    // Forces on vertices 1..3 are the columns of −V P Dm⁻ᵀ; vertex 0 balances them.
    const Matrix3d H = -m_sorted_volume[i] * kernel.P(F) * Dm_inv.transpose();
    for (int k = 0; k < 3; ++k)
      Eigen::Map<Vector3d>(forces + 3 * tet[k + 1]) += H.col(k);
    Eigen::Map<Vector3d>(forces + 3 * tet[0]) -= H.rowwise().sum();
    if (ratios) {
      const SmallestVolumeRatio here{F.determinant(), static_cast<Index>(m_partition.order[i])};
      SmallestVolumeRatio& best = chunk_smallest[chunk];
      if (here.before(best)) best = here;
    }
    return energy ? m_sorted_volume[i] * kernel.psi(F) : 0.0;
  };
  for_each_chunk_colored(m_partition, [&](int chunk) {
    double sum = 0.0;
    int i = m_partition.chunk_begin[chunk];
    const int end = m_partition.chunk_begin[chunk + 1];
    if constexpr (requires { typename Kernel::LaneKernel; }) {
      const typename Kernel::LaneKernel lanes(m_lame);
      for (; i + detail::kLanes <= end; i += detail::kLanes) {
        const int group = i / detail::kLanes;
        const double* lane_Dm_inv = &m_lane_rest[kLaneRest * group];
        const double* lane_volume = lane_Dm_inv + 9 * detail::kLanes;
        if (i + kPrefetchTets + detail::kLanes <= end)
          prefetch_vertices(&m_sorted_tets[4 * (i + kPrefetchTets)], positions, forces);
        double J[detail::kLanes];
        double* volume_ratio = ratios ? J : nullptr;
        sum += energy ? lane_group_forces<true>(lanes, positions, &m_sorted_tets[4 * i],
                                                lane_Dm_inv, lane_volume, forces, volume_ratio)
                      : lane_group_forces<false>(lanes, positions, &m_sorted_tets[4 * i],
                                                 lane_Dm_inv, lane_volume, forces, volume_ratio);
        if (ratios) {
          SmallestVolumeRatio& best = chunk_smallest[chunk];
          for (int l = 0; l < detail::kLanes; ++l) {
            if (J[l] > best.J) continue;  // the common case; NaNs and ties take the full rule
            const SmallestVolumeRatio here{J[l], static_cast<Index>(m_partition.order[i + l])};
            if (here.before(best)) best = here;
          }
        }
      }
    }
    for (; i < end; ++i)
      sum += scalar_tet(i, chunk);
    if (energy) chunk_energy[chunk] = sum;
  });
  if (ratios) {
    SmallestVolumeRatio smallest;
    for (const SmallestVolumeRatio& candidate : chunk_smallest)
      if (candidate.before(smallest)) smallest = candidate;
    *smallest_volume_ratio = {smallest.J, smallest.tet};
  }
  if (energy) {
    *energy = 0.0;
    for (double e : chunk_energy)
      *energy += e;
  }
  m_element_evaluations += num_tets();
}

double ElasticModel::energy(ConstRef<VectorXd> x) const {
  check_size(x, num_dofs());
  std::vector<double> chunk_energy(m_partition.num_chunks(), 0.0);
  // Chunk by chunk, by lane groups where the model has a lane kernel, then a scalar tail.
  dispatch_kernel(m_material.model, m_lame, [&](const auto& kernel) {
    using Kernel = std::decay_t<decltype(kernel)>;
    tbb::parallel_for(Index(0), m_partition.num_chunks(), [&](Index chunk) {
      double sum = 0.0;
      int i = m_partition.chunk_begin[chunk];
      const int end = m_partition.chunk_begin[chunk + 1];
      if constexpr (requires { typename Kernel::LaneKernel; }) {
        const typename Kernel::LaneKernel lanes(m_lame);
        for (; i + detail::kLanes <= end; i += detail::kLanes) {
          const double* lane_Dm_inv = &m_lane_rest[kLaneRest * (i / detail::kLanes)];
          sum += lane_group_energy(lanes, x.data(), &m_sorted_tets[4 * i], lane_Dm_inv,
                                   lane_Dm_inv + 9 * detail::kLanes);
        }
      }
      for (; i < end; ++i) {
        const Eigen::Map<const Matrix3d> Dm_inv(&m_sorted_Dm_inv[9 * i]);
        sum += m_sorted_volume[i] *
               kernel.psi(edge_matrix_at(x.data(), &m_sorted_tets[4 * i]) * Dm_inv);
      }
      chunk_energy[chunk] = sum;
    });
  });
  m_element_evaluations += num_tets();
  double total = 0.0;
  for (double e : chunk_energy)
    total += e;
  return total;
}

void ElasticModel::forces(ConstRef<VectorXd> x, VectorXd& f) const {
  check_size(x, num_dofs());
  f.setZero(num_dofs());
  dispatch_kernel(m_material.model, m_lame,
                  [&](const auto& kernel) { accumulate_forces(kernel, x, f, nullptr, nullptr); });
}

std::pair<double, Index> ElasticModel::forces_and_min_volume_ratio(ConstRef<VectorXd> x,
                                                                   VectorXd& f) const {
  check_size(x, num_dofs());
  f.setZero(num_dofs());
  std::pair<double, Index> smallest;
  dispatch_kernel(m_material.model, m_lame,
                  [&](const auto& kernel) { accumulate_forces(kernel, x, f, nullptr, &smallest); });
  return smallest;
}

double ElasticModel::energy_and_forces(ConstRef<VectorXd> x, VectorXd& f) const {
  check_size(x, num_dofs());
  f.setZero(num_dofs());
  double energy = 0.0;
  dispatch_kernel(m_material.model, m_lame,
                  [&](const auto& kernel) { accumulate_forces(kernel, x, f, &energy, nullptr); });
  return energy;
}

/// Collaborative: a thread that waits for the pattern joins the TBB work that builds it, so a
/// first call from inside a TBB task cannot deadlock.
struct ElasticModel::PatternOnce {
  tbb::collaborative_once_flag flag;
};

ElasticModel::~ElasticModel() = default;

const SparseMatrixd& ElasticModel::stiffness_pattern() const {
  tbb::collaborative_call_once(m_pattern_once->flag, [this] { build_stiffness_pattern(); });
  return m_pattern;
}

void ElasticModel::build_stiffness_pattern() const {
  const Index num_tets = m_tets.rows();
  // Column 3v + c holds, for each neighbour w of v (ascending), the rows 3w, 3w + 1, 3w + 2.
  const CompressedLists neighbours = vertex_neighbours(m_tets, m_num_vertices);
  m_pattern = block_pattern(neighbours, "mesh too large: stiffness matrix");

  m_block_offsets.resize(48 * num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index i) {
    const int* tet = &m_sorted_tets[4 * i];
    for (int b = 0; b < 4; ++b) {
      // The slot of each corner a in b's neighbour list: the count of smaller neighbours.
      int slot[4] = {0, 0, 0, 0};
      for (const int neighbour : neighbours[tet[b]])
        for (int a = 0; a < 4; ++a)
          slot[a] += neighbour < tet[a];
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 3; ++c)
          m_block_offsets[48 * i + 12 * b + 3 * a + c] =
              static_cast<int>(block_column_start(neighbours, tet[b], c)) + 3 * slot[a];
    }
  });
}

namespace {

/// Element stiffness blocks from the generic ∂²ψ/∂F²:
/// K_ab = V Σ_{c,d} ∇N_a[c] ∇N_b[d] · (∂²ψ/∂F_{·c}∂F_{·d}). Plain arrays, as for StVK.
void generic_stiffness_blocks(const Matrix9d& d2psi, const Eigen::Matrix<double, 4, 3>& grad_N,
                              double volume, Matrix3d (&blocks)[4][4]) {
  double g[4][3];
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < 3; ++d)
      g[k][d] = grad_N(k, d);
  const double* H = d2psi.data();  // H[i + 9 j] = d2psi(i, j)
  double right[12][9];             // right[3b + r][i] = Σ_d d2psi(i, 3d + r) ∇N_b[d]
  for (int b = 0; b < 4; ++b)
    for (int r = 0; r < 3; ++r)
      for (int i = 0; i < 9; ++i)
        right[3 * b + r][i] =
            H[i + 9 * r] * g[b][0] + H[i + 9 * (3 + r)] * g[b][1] + H[i + 9 * (6 + r)] * g[b][2];
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q)
          blocks[a][b](q, r) =
              volume * (g[a][0] * right[3 * b + r][q] + g[a][1] * right[3 * b + r][3 + q] +
                        g[a][2] * right[3 * b + r][6 + q]);
}

}  // namespace

void ElasticModel::stiffness(ConstRef<VectorXd> x, SparseMatrixd& K, bool project_psd) const {
  check_size(x, num_dofs());
  const SparseMatrixd& pattern = stiffness_pattern();
  if (K.rows() != pattern.rows() || K.nonZeros() != pattern.nonZeros() ||
      !std::equal(pattern.outerIndexPtr(), pattern.outerIndexPtr() + pattern.outerSize() + 1,
                  K.outerIndexPtr()))
    K = pattern;
  else
    for_each_vector_chunk(K.nonZeros(), [&](Index begin, Index end) {
      std::fill(K.valuePtr() + begin, K.valuePtr() + end, 0.0);
    });
  stiffness_into(x, project_psd, {K.valuePtr(), m_block_offsets.data()});
}

namespace {

/// The value array that tet `tet`'s offsets point into.
double* scatter_values(const StiffnessScatter& scatter, Index tet) {
  return scatter.in_second != nullptr && scatter.in_second[tet] ? scatter.second_values
                                                                : scatter.values;
}

}  // namespace

void ElasticModel::stiffness_into(ConstRef<VectorXd> x, bool project_psd,
                                  const StiffnessScatter& scatter) const {
  check_size(x, num_dofs());
  detail::visit_material_model(m_material.model, [&](auto model_type) {
    using Model = decltype(model_type);
    // A model with a closed-form element stiffness (four tets at a time where it has a lane
    // kernel, one at a time otherwise and for a chunk's last tets) uses it for the exact Hessian;
    // otherwise ∂²ψ/∂F² goes through the generic block product, projected in the singular-value
    // frame when asked.
    constexpr bool kClosedForm = requires {
      Model::stiffness_blocks;
    };
    constexpr bool kClosedFormLanes = requires {
      typename Model::StiffnessLaneKernel;
    };
    const bool closed_form = kClosedForm && !project_psd;
    for_each_chunk_colored(m_partition, [&](int chunk) {
      int i = m_partition.chunk_begin[chunk];
      const int end = m_partition.chunk_begin[chunk + 1];
      if constexpr (kClosedFormLanes) {
        if (closed_form) {
          using detail::kLanes;
          const typename Model::StiffnessLaneKernel lanes(m_lame);
          double lane_K[kLanes][12][12];
          for (; i + kLanes <= end; i += kLanes) {
            const double* lane_Dm_inv = &m_lane_rest[kLaneRest * (i / kLanes)];
            // The value array is far larger than the caches: fetch the next group's entries while
            // this group's blocks are computed.
            if (i + 2 * kLanes <= end)
              for (int l = kLanes; l < 2 * kLanes; ++l)
                detail::prefetch_block_entries(&scatter.offsets[48 * Index(i + l)],
                                               scatter_values(scatter, i + l));
            double F[3][3][kLanes];
            detail::lane_deformation_gradient(x.data(), &m_sorted_tets[4 * i], lane_Dm_inv, F);
            lanes(F, lane_Dm_inv, lane_Dm_inv + 9 * kLanes, lane_K);
            for (int l = 0; l < kLanes; ++l)
              detail::scatter_element_stiffness(lane_K[l], &scatter.offsets[48 * Index(i + l)],
                                                scatter_values(scatter, i + l));
          }
        }
      }
      Matrix3d blocks[4][4];
      for (; i < end; ++i) {
        const int* tet = &m_sorted_tets[4 * i];
        const Eigen::Map<const Matrix3d> Dm_inv(&m_sorted_Dm_inv[9 * i]);
        const Matrix3d F = edge_matrix_at(x.data(), tet) * Dm_inv;
        const Eigen::Matrix<double, 4, 3> grad_N = shape_function_gradients(Dm_inv);
        bool done = false;
        if constexpr (kClosedForm) {
          if (closed_form) {
            Model::stiffness_blocks(F, grad_N, m_lame, m_sorted_volume[i], blocks);
            done = true;
          }
        }
        if (!done) {
          Matrix9d d2psi;
          if (project_psd) {
            SingularFrameHessian frame;
            frame.svd = rotation_variant_svd(F);
            Model::singular_frame(frame.svd.sigma, m_lame, frame);
            d2psi = frame_hessian_matrix(frame, true);
          } else {
            d2psi = Model::hessian(F, m_lame);
          }
          generic_stiffness_blocks(d2psi, grad_N, m_sorted_volume[i], blocks);
        }
        const int* offsets = &scatter.offsets[48 * Index(i)];
        double* values = scatter_values(scatter, i);
        for (int b = 0; b < 4; ++b)
          for (int a = 0; a < 4; ++a)
            for (int c = 0; c < 3; ++c) {
              double* entry = values + offsets[12 * b + 3 * a + c];
              entry[0] += blocks[a][b](0, c);
              entry[1] += blocks[a][b](1, c);
              entry[2] += blocks[a][b](2, c);
            }
      }
    });
  });
  m_element_evaluations += num_tets();
}

std::pair<double, Index> ElasticModel::min_volume_ratio(ConstRef<VectorXd> x) const {
  check_size(x, num_dofs());
  // J = det(Ds Dm⁻¹) = det(Ds) det(Dm⁻¹), over the sorted tets in parallel. The smallest J wins,
  // a NaN before any number, ties to the smaller tet index: the same answer on any schedule.
  using Smallest = SmallestVolumeRatio;
  const double* p = x.data();
  const Smallest smallest = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, num_tets(), 8192), Smallest{},
      [&](const tbb::blocked_range<Index>& range, Smallest best) {
        for (Index i = range.begin(); i != range.end(); ++i) {
          const int* tet = &m_sorted_tets[4 * i];
          const Vector3d x0(p[3 * tet[0]], p[3 * tet[0] + 1], p[3 * tet[0] + 2]);
          const Vector3d e1 = Vector3d(p[3 * tet[1]], p[3 * tet[1] + 1], p[3 * tet[1] + 2]) - x0;
          const Vector3d e2 = Vector3d(p[3 * tet[2]], p[3 * tet[2] + 1], p[3 * tet[2] + 2]) - x0;
          const Vector3d e3 = Vector3d(p[3 * tet[3]], p[3 * tet[3] + 1], p[3 * tet[3] + 2]) - x0;
          const Smallest here{e1.dot(e2.cross(e3)) * m_sorted_Dm_inv_det[i],
                              static_cast<Index>(m_partition.order[i])};
          if (here.before(best)) best = here;
        }
        return best;
      },
      [](const Smallest& a, const Smallest& b) { return a.before(b) ? a : b; });
  return {smallest.J, smallest.tet};
}

Eigen::Matrix<double, Eigen::Dynamic, 6> ElasticModel::green_strains(ConstRef<VectorXd> x) const {
  check_size(x, num_dofs());
  Eigen::Matrix<double, Eigen::Dynamic, 6> strains(num_tets(), 6);
  tbb::parallel_for(Index(0), num_tets(), [&](Index t) {
    int tet[4] = {m_tets(t, 0), m_tets(t, 1), m_tets(t, 2), m_tets(t, 3)};
    const Matrix3d F = edge_matrix_at(x.data(), tet) * m_rest.Dm_inv[t];
    strains.row(t) = to_voigt(green_strain(F)).transpose();
  });
  return strains;
}

TetFields ElasticModel::tet_fields(ConstRef<VectorXd> x) const {
  check_size(x, num_dofs());
  TetFields fields;
  fields.green_strain = green_strains(x);  // the same bits as green_strains alone
  fields.cauchy_stress.resize(num_tets(), 6);
  fields.von_mises.resize(num_tets());
  tbb::parallel_for(Index(0), num_tets(), [&](Index t) {
    int tet[4] = {m_tets(t, 0), m_tets(t, 1), m_tets(t, 2), m_tets(t, 3)};
    const Matrix3d F = edge_matrix_at(x.data(), tet) * m_rest.Dm_inv[t];
    const Matrix3d Fe = m_plastic_inverse.empty() ? F : Matrix3d(F * m_plastic_inverse[t]);
    const Matrix3d sigma = cauchy_stress(dpsi_dF(m_material.model, Fe, m_lame), Fe);
    fields.cauchy_stress.row(t) = to_voigt(sigma).transpose();
    fields.von_mises[t] = von_mises_stress(sigma);
  });
  return fields;
}

}  // namespace strata
