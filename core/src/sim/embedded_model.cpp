#include "strata/core/sim/embedded_model.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>

#include "strata/core/common/compressed_lists.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/common/parallel.hpp"
#include "strata/core/common/vector_chunks.hpp"
#include "strata/core/sim/stable_time_step.hpp"

namespace strata {

namespace {

double rest_edge_length_mean(const ElasticModel& model) {
  return mean_edge_length(unflatten(model.rest_positions()), model.tets());
}

/// The neighbours of each mesh vertex (the corners of its tets, itself included) and, of those,
/// the corners of its tets with `in_layer` set: two sorted lists per vertex, from one gather.
std::pair<CompressedLists, CompressedLists> neighbour_lists(
    const CompressedLists& incident, const std::vector<int>& sorted_tets,
    const std::vector<std::uint8_t>& in_layer, Index num_vertices) {
  STRATA_VERIFY(num_vertices <= std::numeric_limits<int>::max(),
                "embedding: too many mesh vertices");
  std::pair<CompressedLists, CompressedLists> result;
  CompressedLists& all = result.first;
  CompressedLists& layer = result.second;
  all.offsets.assign(num_vertices + 1, 0);
  layer.offsets.assign(num_vertices + 1, 0);
  if (num_vertices == 0) return result;
  // Fixed chunks, each collecting its lists in buffers of its own (join_chunk_lists).
  const Index num_chunks = std::min<Index>(num_vertices, 256);
  std::vector<std::vector<int>> chunk_all(num_chunks), chunk_layer(num_chunks);
  struct Seen {
    std::vector<int> by;              // the vertex whose list last took each entry
    std::vector<std::uint8_t> layer;  // whether that list reached it through a layer tet
  };
  tbb::enumerable_thread_specific<Seen> seen_lists([&] {
    return Seen{std::vector<int>(num_vertices, -1), std::vector<std::uint8_t>(num_vertices)};
  });
  tbb::parallel_for(Index(0), num_chunks, [&](Index c) {
    const Index begin = num_vertices * c / num_chunks, end = num_vertices * (c + 1) / num_chunks;
    Seen& seen = seen_lists.local();
    std::vector<int>& out = chunk_all[c];
    std::vector<int>& out_layer = chunk_layer[c];
    for (Index w = begin; w < end; ++w) {
      const auto first = out.size();
      for (const int t : incident[w]) {
        const std::uint8_t layer_tet = in_layer[t];
        for (const int v : std::span<const int>(&sorted_tets[4 * t], 4)) {
          if (seen.by[v] == static_cast<int>(w)) {
            seen.layer[v] |= layer_tet;
            continue;
          }
          seen.by[v] = static_cast<int>(w);
          seen.layer[v] = layer_tet;
          out.push_back(v);
        }
      }
      std::sort(out.begin() + first, out.end());
      const auto first_layer = out_layer.size();
      for (auto k = first; k < out.size(); ++k)
        if (seen.layer[out[k]]) out_layer.push_back(out[k]);
      all.offsets[w + 1] = static_cast<Index>(out.size() - first);
      layer.offsets[w + 1] = static_cast<Index>(out_layer.size() - first_layer);
    }
  });
  join_chunk_lists(all, chunk_all);
  join_chunk_lists(layer, chunk_layer);
  return result;
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
  // x_v = Σ_q C_vq q_q, vertex by vertex (the columns of Cᵀ), in parallel.
  VectorXd x(3 * m_C.rows());
  for_each_vector_chunk(m_C.rows(), [&](Index begin, Index end) {
    for (Index v = begin; v < end; ++v) {
      Vector3d sum = Vector3d::Zero();
      for (SparseMatrixd::InnerIterator it(m_CT, v); it; ++it)
        sum += it.value() * q.segment<3>(3 * it.index());
      x.segment<3>(3 * v) = sum;
    }
  });
  return x;
}

VectorXd EmbeddedElasticModel::reduce(ConstRef<VectorXd> f) const {
  if (m_identity) return f;
  // r_q = Σ_v C_vq f_v, DOF vertex by DOF vertex (the columns of C), in parallel.
  VectorXd r(3 * m_num_dof_vertices);
  for_each_vector_chunk(m_num_dof_vertices, [&](Index begin, Index end) {
    for (Index q = begin; q < end; ++q) {
      Vector3d sum = Vector3d::Zero();
      for (SparseMatrixd::InnerIterator it(m_C, q); it; ++it)
        sum += it.value() * f.segment<3>(3 * it.index());
      r.segment<3>(3 * q) = sum;
    }
  });
  return r;
}

VectorXd EmbeddedElasticModel::reduce_vertex_scalar(ConstRef<VectorXd> s) const {
  if (m_identity) return s;
  return m_CT * s;
}

VectorXd EmbeddedElasticModel::at_dof_vertices(ConstRef<VectorXd> on_dofs) const {
  if (m_identity) return on_dofs;
  VectorXd on_mesh = VectorXd::Zero(3 * m_C.rows());
  for (Index q = 0; q < m_num_dof_vertices; ++q)
    on_mesh.segment<3>(3 * Index(m_dof_vertices[q])) = on_dofs.segment<3>(3 * q);
  return on_mesh;
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
  if (K.rows() != m_pattern.rows() || K.nonZeros() != m_pattern.nonZeros() ||
      !std::equal(m_pattern.outerIndexPtr(), m_pattern.outerIndexPtr() + m_pattern.outerSize() + 1,
                  K.outerIndexPtr()))
    K = m_pattern;
  double* values = K.valuePtr();
  for_each_vector_chunk(
      K.nonZeros(), [&](Index begin, Index end) { std::fill(values + begin, values + end, 0.0); });
  m_layer_values.resize(3 * m_num_layer_blocks);
  for_each_vector_chunk(static_cast<Index>(m_layer_values.size()), [&](Index begin, Index end) {
    std::fill(m_layer_values.data() + begin, m_layer_values.data() + end, 0.0);
  });
  m_model->stiffness_into(expand(q), project_psd,
                          {values, m_offsets.data(), m_in_layer.data(), m_layer_values.data()});
  // The layer's blocks into their targets, DOF vertex by DOF vertex (each column of K_q's values
  // receives its additions in a fixed order, whatever the thread count).
  const double* source = m_layer_values.data();
  const LayerAddition* additions = m_layer_additions.data();
  tbb::parallel_for(tbb::blocked_range<Index>(0, m_num_dof_vertices, 256),
                    [&](const tbb::blocked_range<Index>& columns) {
                      for (Index k = m_column_begin[columns.begin()];
                           k < m_column_begin[columns.end()]; ++k) {
                        const LayerAddition& addition = additions[k];
                        const double* block = source + 3 * Index(addition.block);
                        for (int i = 0; i < 3; ++i)
                          values[addition.target + i] += addition.weight * block[i];
                      }
                    });
}

void EmbeddedElasticModel::build_reduced_pattern() {
  // Mesh vertices v, w are neighbours when a tet holds both; an element block (v, w) feeds the
  // reduced blocks (a, b) for C_va ≠ 0, C_wb ≠ 0 with weight C_va C_wb.
  const MatrixX4i& tets = m_model->tets();
  const Index num_mesh_vertices = m_C.rows();
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  const RowMajor C_rows = m_C;
  const int* row_outer = C_rows.outerIndexPtr();
  const int* row_inner = C_rows.innerIndexPtr();
  const double* row_values = C_rows.valuePtr();

  // The tets of each mesh vertex, in the mesh model's order (ElasticModel::sorted_tets).
  const std::vector<int>& sorted_tets = m_model->sorted_tets();
  const Index num_tets = tets.rows();
  CompressedLists incident;
  {
    CompressedLists tet_lists;
    tet_lists.offsets.resize(num_tets + 1);
    for (Index t = 0; t <= num_tets; ++t)
      tet_lists.offsets[t] = 4 * t;
    tet_lists.indices = sorted_tets;
    incident = transpose_lists(tet_lists, num_mesh_vertices);
  }

  // A mesh vertex whose C row is e_q for its own DOF vertex q is direct. Distinct direct vertices
  // have distinct DOF vertices, so tets of direct vertices that share no vertex share no target.
  std::vector<int> direct_dof(num_mesh_vertices, -1);
  for (Index q = 0; q < m_num_dof_vertices; ++q) {
    const int v = m_dof_vertices[q];
    if (row_outer[v + 1] - row_outer[v] == 1 && row_values[row_outer[v]] == 1.0)
      direct_dof[v] = static_cast<int>(q);
  }

  // The layer: the tets with a vertex that is not direct, and the blocks of their vertices.
  m_in_layer.resize(num_tets);
  tbb::parallel_for(Index(0), num_tets, [&](Index t) {
    const int* tet = &sorted_tets[4 * t];
    m_in_layer[t] = direct_dof[tet[0]] < 0 || direct_dof[tet[1]] < 0 || direct_dof[tet[2]] < 0 ||
                    direct_dof[tet[3]] < 0;
  });
  m_num_layer_tets = std::count(m_in_layer.begin(), m_in_layer.end(), std::uint8_t(1));
  const std::pair<CompressedLists, CompressedLists> lists =
      neighbour_lists(incident, sorted_tets, m_in_layer, num_mesh_vertices);
  const CompressedLists& neighbours = lists.first;
  const CompressedLists& layer = lists.second;

  // Block pattern: the reduced neighbours a of DOF vertex b.
  const CompressedLists blocks = sorted_unique_lists(
      m_num_dof_vertices, m_num_dof_vertices, [&](Index b, std::vector<int>& out) {
        for (SparseMatrixd::InnerIterator w(m_C, b); w; ++w)
          for (const int v : neighbours[w.row()])
            out.insert(out.end(), row_inner + row_outer[v], row_inner + row_outer[v + 1]);
      });
  if (9 * layer.indices.size() > std::size_t(std::numeric_limits<int>::max()))
    throw InputError("embedding: reduced stiffness matrix exceeds 2^31 entries");

  // The scalar pattern of K_q and the assembly plan (element offsets, the layer's targets) are
  // built side by side: neither reads what the other writes.
  SparseMatrixd pattern;
  const auto plan = [&] {
    // Element block offsets, vertex by vertex: for each tet of w (local corner b), the blocks (a,
    // b) of its corners a in K_q's values (a direct tet: w's DOF vertex's list) or in the layer's
    // (w's layer list). The threads write disjoint entries (one corner of a tet each).
    m_offsets.resize(48 * num_tets);
    tbb::enumerable_thread_specific<std::vector<int>> layer_slots(
        [&] { return std::vector<int>(num_mesh_vertices, -1); });
    tbb::enumerable_thread_specific<std::vector<int>> dof_slots(
        [&] { return std::vector<int>(m_num_dof_vertices, -1); });
    tbb::parallel_for(Index(0), num_mesh_vertices, [&](Index w) {
      std::vector<int>& layer_slot = layer_slots.local();
      std::vector<int>& dof_slot = dof_slots.local();
      const std::span<const int> layer_list = layer[w];
      for (std::size_t k = 0; k < layer_list.size(); ++k)
        layer_slot[layer_list[k]] = static_cast<int>(k);
      const int b_dof = direct_dof[w];
      const std::span<const int> dof_list = b_dof >= 0 ? blocks[b_dof] : std::span<const int>();
      for (std::size_t k = 0; k < dof_list.size(); ++k)
        dof_slot[dof_list[k]] = static_cast<int>(k);
      const Index layer_start = block_column_start(layer, w, 0);
      const Index layer_column = 3 * layer.list_size(w);
      const Index dof_start = b_dof >= 0 ? block_column_start(blocks, b_dof, 0) : 0;
      const Index dof_column = b_dof >= 0 ? 3 * blocks.list_size(b_dof) : 0;
      int* all_offsets = m_offsets.data();
      for (const int t : incident[w]) {
        const int corners[4] = {sorted_tets[4 * t], sorted_tets[4 * t + 1], sorted_tets[4 * t + 2],
                                sorted_tets[4 * t + 3]};
        const int b =
            static_cast<int>(std::find(corners, corners + 4, static_cast<int>(w)) - corners);
        const bool in_layer = m_in_layer[t];
        const Index start = in_layer ? layer_start : dof_start;
        const Index column_length = in_layer ? layer_column : dof_column;
        int slots[4];
        for (int a = 0; a < 4; ++a)
          slots[a] = in_layer ? layer_slot[corners[a]] : dof_slot[direct_dof[corners[a]]];
        int* offsets = all_offsets + 48 * Index(t);
        for (int a = 0; a < 4; ++a)
          for (int c = 0; c < 3; ++c)
            offsets[12 * b + 3 * a + c] =
                static_cast<int>(start + 3 * slots[a] + c * column_length);
      }
      for (const int v : layer_list)
        layer_slot[v] = -1;
      for (const int q : dof_list)
        dof_slot[q] = -1;
    });
  };
  // The layer's additions, DOF vertex b by DOF vertex: for each column j of b's block column, the
  // mesh vertices w of C's column b (ascending), their layer blocks (v, w) (v ascending) and the
  // entries C_va of v's row, adding C_va C_wb (v, w) to K_q's block (a, b). Each value of K_q so
  // receives its additions in the order of the layer's blocks.
  const auto additions = [&] {
    const Index n = m_num_dof_vertices;
    m_column_begin.assign(n + 1, 0);
    tbb::parallel_for(Index(0), n, [&](Index b) {
      Index count = 0;
      for (SparseMatrixd::InnerIterator w(m_C, b); w; ++w)
        for (const int v : layer[w.row()])
          count += row_outer[v + 1] - row_outer[v];
      m_column_begin[b + 1] = 3 * count;
    });
    for (Index b = 0; b < n; ++b)
      m_column_begin[b + 1] += m_column_begin[b];
    m_layer_additions.resize(m_column_begin[n]);
    tbb::enumerable_thread_specific<std::vector<int>> slots_of(
        [&] { return std::vector<int>(n, -1); });
    tbb::parallel_for(Index(0), n, [&](Index b) {
      std::vector<int>& slot = slots_of.local();
      const std::span<const int> b_list = blocks[b];
      for (std::size_t k = 0; k < b_list.size(); ++k)
        slot[b_list[k]] = static_cast<int>(k);
      LayerAddition* out = m_layer_additions.data() + m_column_begin[b];
      for (int j = 0; j < 3; ++j) {
        const Index column = block_column_start(blocks, b, j);
        for (SparseMatrixd::InnerIterator w(m_C, b); w; ++w) {
          const std::span<const int> list = layer[w.row()];
          const Index first_block = block_column_start(layer, w.row(), j) / 3;
          for (std::size_t k = 0; k < list.size(); ++k) {
            const int v = list[k];
            for (int ia = row_outer[v]; ia < row_outer[v + 1]; ++ia)
              *out++ = {static_cast<int>(first_block + static_cast<Index>(k)),
                        static_cast<int>(column + 3 * slot[row_inner[ia]]),
                        row_values[ia] * w.value()};
          }
        }
      }
      for (const int a : b_list)
        slot[a] = -1;
    });
  };
  tbb::parallel_invoke(
      [&] {
        SparseMatrixd built = block_pattern(blocks, "embedding: reduced stiffness matrix");
        pattern.swap(built);  // Eigen's assignment from a named matrix would copy it
      },
      plan, additions);
  m_pattern.swap(pattern);
  m_num_layer_blocks = 3 * static_cast<Index>(layer.indices.size());
}

}  // namespace strata
