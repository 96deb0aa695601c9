#include "strata/core/sim/embedded_model.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "strata/core/common/compressed_lists.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/sim/stable_time_step.hpp"

namespace strata {

namespace {

double rest_edge_length_mean(const ElasticModel& model) {
  return mean_edge_length(unflatten(model.rest_positions()), model.tets());
}

}  // namespace

EmbeddedElasticModel::EmbeddedElasticModel(const ElasticModel& model)
    : m_model(&model),
      m_identity(true),
      m_num_dof_vertices(model.num_vertices()),
      m_rest_positions(model.rest_positions()),
      m_total_rest_volume(model.rest_data().rest_volume.sum()),
      m_mean_edge_length(rest_edge_length_mean(model)) {
  m_dof_vertices.resize(m_num_dof_vertices);
  for (Index v = 0; v < m_num_dof_vertices; ++v)
    m_dof_vertices[v] = static_cast<int>(v);
}

EmbeddedElasticModel::EmbeddedElasticModel(const ElasticModel& model,
                                           SparseMatrixd vertex_embedding,
                                           std::vector<int> dof_vertices)
    : m_model(&model),
      m_identity(false),
      m_num_dof_vertices(static_cast<Index>(dof_vertices.size())),
      m_dof_vertices(std::move(dof_vertices)),
      m_total_rest_volume(model.rest_data().rest_volume.sum()),
      m_mean_edge_length(rest_edge_length_mean(model)),
      m_C(std::move(vertex_embedding)) {
  const Index num_vertices = model.num_vertices();
  if (m_C.rows() != num_vertices || m_C.cols() != m_num_dof_vertices)
    throw InputError("embedding: expected a " + std::to_string(num_vertices) + " x " +
                     std::to_string(m_num_dof_vertices) + " matrix, got " +
                     std::to_string(m_C.rows()) + " x " + std::to_string(m_C.cols()));
  m_C.makeCompressed();
  m_CT = m_C.transpose();
  VectorXd row_sums = VectorXd::Zero(num_vertices);
  for (Index q = 0; q < m_C.outerSize(); ++q)
    for (SparseMatrixd::InnerIterator it(m_C, q); it; ++it) {
      if (!(it.value() >= 0.0))
        throw InputError("embedding: negative weight in row " + std::to_string(it.row()));
      row_sums[it.row()] += it.value();
    }
  for (Index v = 0; v < num_vertices; ++v)
    if (std::abs(row_sums[v] - 1.0) > 1e-12)
      throw InputError("embedding: row " + std::to_string(v) + " sums to " +
                       std::to_string(row_sums[v]) + ", not 1");
  for (Index q = 0; q < m_num_dof_vertices; ++q) {
    const int v = m_dof_vertices[q];
    if (v < 0 || v >= num_vertices || m_C.coeff(v, q) != 1.0)
      throw InputError("embedding: DOF vertex " + std::to_string(q) +
                       " has no identity row (mesh vertex " + std::to_string(v) + ")");
  }
  // C = I (every vertex a DOF vertex, in order; with the identity rows above, #V non-zeros
  // leave no room for anything else): the identity path, without a reduced pattern.
  bool in_order = m_num_dof_vertices == num_vertices && m_C.nonZeros() == num_vertices;
  for (Index q = 0; in_order && q < m_num_dof_vertices; ++q)
    in_order = m_dof_vertices[q] == q;
  if (in_order) {
    m_identity = true;
    m_C.resize(0, 0);
    m_CT.resize(0, 0);
    m_rest_positions = model.rest_positions();
    return;
  }
  m_rest_positions.resize(3 * m_num_dof_vertices);
  for (Index q = 0; q < m_num_dof_vertices; ++q)
    m_rest_positions.segment<3>(3 * q) = model.rest_positions().segment<3>(3 * m_dof_vertices[q]);
  build_reduced_pattern();
}

VectorXd EmbeddedElasticModel::expand(ConstRef<VectorXd> q) const {
  if (m_identity) return q;
  VectorXd x(3 * m_C.rows());
  const Eigen::Map<const Eigen::MatrixXd> qm(q.data(), 3, m_num_dof_vertices);
  Eigen::Map<Eigen::MatrixXd> xm(x.data(), 3, m_C.rows());
  xm.noalias() = qm * m_CT;  // (3 × #Q)(#Q × #V): x_v = Σ_q C_vq q_q
  return x;
}

VectorXd EmbeddedElasticModel::reduce(ConstRef<VectorXd> f) const {
  if (m_identity) return f;
  VectorXd r(3 * m_num_dof_vertices);
  const Eigen::Map<const Eigen::MatrixXd> fm(f.data(), 3, m_C.rows());
  Eigen::Map<Eigen::MatrixXd> rm(r.data(), 3, m_num_dof_vertices);
  rm.noalias() = fm * m_C;  // r_q = Σ_v C_vq f_v
  return r;
}

VectorXd EmbeddedElasticModel::reduce_vertex_scalar(ConstRef<VectorXd> s) const {
  if (m_identity) return s;
  return m_CT * s;
}

double EmbeddedElasticModel::energy(ConstRef<VectorXd> q) const {
  if (m_identity) return m_model->energy(q);
  return m_model->energy(expand(q));
}

void EmbeddedElasticModel::forces(ConstRef<VectorXd> q, VectorXd& f) const {
  if (m_identity) {
    m_model->forces(q, f);
    return;
  }
  VectorXd f_mesh;
  m_model->forces(expand(q), f_mesh);
  f = reduce(f_mesh);
}

const SparseMatrixd& EmbeddedElasticModel::stiffness_pattern() const {
  return m_identity ? m_model->stiffness_pattern() : m_pattern;
}

void EmbeddedElasticModel::stiffness(ConstRef<VectorXd> q, SparseMatrixd& K,
                                     bool project_psd) const {
  if (m_identity) {
    m_model->stiffness(q, K, project_psd);
    return;
  }
  m_model->stiffness(expand(q), m_mesh_stiffness, project_psd);
  if (K.nonZeros() != m_pattern.nonZeros() || K.rows() != m_pattern.rows()) K = m_pattern;
  double* values = K.valuePtr();
  std::fill(values, values + K.nonZeros(), 0.0);
  const double* source = m_mesh_stiffness.valuePtr();
  const WeightedTarget* weighted = m_weighted_targets.data();
  for (const int target : m_block_targets) {
    if (target >= 0) {
      for (int i = 0; i < 3; ++i)
        values[target + i] += source[i];
    } else {
      for (int n = 0; n < ~target; ++n, ++weighted)
        for (int i = 0; i < 3; ++i)
          values[weighted->target + i] += weighted->weight * source[i];
    }
    source += 3;
  }
}

void EmbeddedElasticModel::build_reduced_pattern() {
  // The mesh stiffness is 3×3-block dense: column 3w+j holds rows 3v..3v+2 contiguously for every
  // neighbour v of w. A block (v, w) feeds the reduced blocks (a, b) for C_va ≠ 0, C_wb ≠ 0 with
  // weight C_va C_wb, column by column (3 contiguous values each).
  const SparseMatrixd& mesh_pattern = m_model->stiffness_pattern();
  const int* mesh_outer = mesh_pattern.outerIndexPtr();
  const int* mesh_inner = mesh_pattern.innerIndexPtr();
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  const RowMajor C_rows = m_C;
  const int* row_outer = C_rows.outerIndexPtr();
  const int* row_inner = C_rows.innerIndexPtr();
  const double* row_values = C_rows.valuePtr();

  // Block pattern: the reduced neighbours a of DOF vertex b.
  const CompressedLists blocks = sorted_unique_lists(
      m_num_dof_vertices, m_num_dof_vertices, [&](Index b, std::vector<int>& out) {
        for (SparseMatrixd::InnerIterator w(m_C, b); w; ++w)
          for (int k = mesh_outer[3 * w.row()]; k < mesh_outer[3 * w.row() + 1]; k += 3) {
            const int v = mesh_inner[k] / 3;
            out.insert(out.end(), row_inner + row_outer[v], row_inner + row_outer[v + 1]);
          }
      });

  m_pattern = block_pattern(blocks, "embedding: reduced stiffness matrix");

  // The targets of the mesh blocks, in the order of the mesh values: the columns (w, j), their
  // blocks v, then the entries C_va, C_wb. A block whose C rows are single entries of weight 1
  // (no hanging vertex) adds to one reduced block directly.
  const Index num_mesh_vertices = m_C.rows();
  auto direct = [&](int row) {
    return row_outer[row + 1] - row_outer[row] == 1 && row_values[row_outer[row]] == 1.0;
  };
  std::vector<Index> first_weighted(num_mesh_vertices + 1, 0);
  tbb::parallel_for(Index(0), num_mesh_vertices, [&](Index w) {
    // The three columns of a vertex hold the same blocks (the mesh pattern is 3 × 3 dense).
    const int column_length = mesh_outer[3 * w + 1] - mesh_outer[3 * w];
    STRATA_VERIFY(mesh_outer[3 * w + 2] - mesh_outer[3 * w + 1] == column_length &&
                      mesh_outer[3 * w + 3] - mesh_outer[3 * w + 2] == column_length,
                  "embedding: the mesh stiffness pattern is not made of 3 × 3 blocks");
    const Index w_entries = row_outer[w + 1] - row_outer[w];
    Index count = 0;
    for (int k = mesh_outer[3 * w]; k < mesh_outer[3 * w + 1]; k += 3) {
      const int v = mesh_inner[k] / 3;
      if (!direct(v) || !direct(static_cast<int>(w)))
        count += (row_outer[v + 1] - row_outer[v]) * w_entries;
    }
    first_weighted[w + 1] = 3 * count;
  });
  for (Index w = 0; w < num_mesh_vertices; ++w)
    first_weighted[w + 1] += first_weighted[w];
  if (mesh_pattern.nonZeros() / 3 > std::numeric_limits<int>::max() ||
      first_weighted[num_mesh_vertices] > std::numeric_limits<int>::max())
    throw InputError("embedding: reduced stiffness matrix exceeds 2^31 entries");

  m_block_targets.resize(mesh_pattern.nonZeros() / 3);
  m_weighted_targets.resize(first_weighted[num_mesh_vertices]);
  // Per thread, the slot of each block row in the list of a DOF vertex b (for w with C_w = e_b).
  tbb::enumerable_thread_specific<std::vector<int>> slots_of(
      [&] { return std::vector<int>(m_num_dof_vertices, -1); });
  tbb::parallel_for(Index(0), num_mesh_vertices, [&](Index w) {
    const bool single = row_outer[w + 1] - row_outer[w] == 1;
    const bool w_direct = direct(static_cast<int>(w));
    std::vector<int>& slot_of = slots_of.local();
    if (single) {
      const std::span<const int> list = blocks[row_inner[row_outer[w]]];
      for (std::size_t slot = 0; slot < list.size(); ++slot)
        slot_of[list[slot]] = static_cast<int>(slot);
    }
    auto target = [&](int a, int b, int j) {
      Index slot;
      if (single) {
        slot = slot_of[a];
      } else {
        const std::span<const int> list = blocks[b];
        slot = std::lower_bound(list.begin(), list.end(), a) - list.begin();
      }
      return static_cast<int>(block_column_start(blocks, b, j) + 3 * slot);
    };
    Index position = first_weighted[w];
    for (int j = 0; j < 3; ++j)
      for (int k = mesh_outer[3 * w + j]; k < mesh_outer[3 * w + j + 1]; k += 3) {
        const int v = mesh_inner[k] / 3;
        if (w_direct && direct(v)) {
          m_block_targets[k / 3] = target(row_inner[row_outer[v]], row_inner[row_outer[w]], j);
          continue;
        }
        const Index first = position;
        for (int ia = row_outer[v]; ia < row_outer[v + 1]; ++ia)
          for (int ib = row_outer[w]; ib < row_outer[w + 1]; ++ib)
            m_weighted_targets[position++] = {target(row_inner[ia], row_inner[ib], j),
                                              row_values[ia] * row_values[ib]};
        m_block_targets[k / 3] = ~static_cast<int>(position - first);
      }
  });
}

}  // namespace strata
