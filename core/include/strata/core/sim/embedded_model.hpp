#pragma once
/// \file embedded_model.hpp
/// The elastic model seen through a linear embedding of the mesh vertices in the simulation DOFs:
///
///     x = P q,   P = C ⊗ I₃,   C: #V × #Q (scalar, applied to each coordinate),
///
/// with x the 3·#V mesh positions and q the 3·#Q positions of the *DOF vertices*. Every integrator
/// and the static solver run on q through this class, so a mesh with hanging vertices (an active
/// cut of the refinement tree, whose hanging vertices interpolate coarser edges) and a plain mesh
/// (C = I, the default: no copies, no overhead) take the same code path.
///
/// Reduced quantities are energy-consistent: Ψ_q(q) = Ψ(P q), f_q = Pᵀ f(P q),
/// K_q = Pᵀ K(P q) P (PSD whenever K is, so PSD-projected element Hessians stay PSD). K_q is
/// assembled into a fixed pattern computed once, without the whole mesh-level K: a tet whose four
/// vertices are DOF vertices (C rows e_q) adds its element stiffness straight to K_q in the mesh
/// model's parallel pass; the tets that touch a hanging vertex (a thin layer where levels meet)
/// assemble a mesh-level matrix of their own vertex blocks, each of whose blocks (v, w) then adds
/// to the reduced blocks (a, b) with weight C_va C_wb. Those additions are listed once per
/// embedding by the DOF vertex b whose block column they add to, each value's in the order of the
/// layer's blocks, and the block columns add in parallel: every value receives its additions in
/// one fixed order, so the result does not depend on the thread count.
///
/// Requirements on C (checked, InputError): every row sums to 1 with non-negative entries
/// (partition of unity: affine fields and rigid motions are reproduced exactly) and each DOF
/// vertex q has an identity row (`dof_vertices[q]` is a mesh vertex with C(dof_vertices[q], ·) =
/// e_q). The rest positions of the DOFs are those of their mesh vertices.
///
/// Not thread-safe: `stiffness` reuses a scratch buffer.
#include <cstdint>
#include <vector>

#include "strata/core/common/fill_vector.hpp"
#include "strata/core/common/types.hpp"
#include "strata/core/fem/elastic_model.hpp"

namespace strata {

class EmbeddedElasticModel {
 public:
  /// The identity embedding: q = x. `model` must outlive this object.
  explicit EmbeddedElasticModel(const ElasticModel& model);
  /// x = (C ⊗ I₃) q with `vertex_embedding` = C (#V × #Q) and `dof_vertices` (#Q) the mesh vertex
  /// of each DOF vertex. Throws InputError if C violates the requirements above. C = I with the
  /// DOF vertices in mesh order (a cut without hanging vertices) takes the identity path.
  EmbeddedElasticModel(const ElasticModel& model, SparseMatrixd vertex_embedding,
                       std::vector<int> dof_vertices);

  bool is_identity() const { return m_identity; }
  const ElasticModel& mesh_model() const { return *m_model; }
  const Material& material() const { return m_model->material(); }

  Index num_dof_vertices() const { return m_num_dof_vertices; }  ///< #Q
  Index num_dofs() const { return 3 * m_num_dof_vertices; }      ///< 3·#Q
  /// The mesh vertex of each DOF vertex (#Q; 0..#V−1 for the identity).
  const std::vector<int>& dof_vertices() const { return m_dof_vertices; }
  /// Rest positions of the DOF vertices, 3·#Q.
  const VectorXd& rest_positions() const { return m_rest_positions; }
  /// Σ rest volumes of the mesh's tets [m³].
  double total_rest_volume() const { return m_total_rest_volume; }
  /// Mean rest edge length of the mesh [m].
  double mean_edge_length() const { return m_mean_edge_length; }
  /// C (#V × #Q); empty for the identity.
  const SparseMatrixd& vertex_embedding() const { return m_C; }

  /// x = P q (3·#Q → 3·#V).
  VectorXd expand(ConstRef<VectorXd> q) const;
  /// Pᵀ f (3·#V → 3·#Q): forces, loads.
  VectorXd reduce(ConstRef<VectorXd> f) const;
  /// Cᵀ s (#V → #Q): lumped vertex masses (total mass kept since C·1 = 1).
  VectorXd reduce_vertex_scalar(ConstRef<VectorXd> s) const;
  /// A vector on the DOFs (3·#Q) placed at the DOF vertices' mesh vertices (3·#V), zero at the
  /// others (hanging vertices): point values such as forces, not an interpolation.
  VectorXd at_dof_vertices(ConstRef<VectorXd> on_dofs) const;

  /// Ψ(P q) [J].
  double energy(ConstRef<VectorXd> q) const;
  /// f_q = Pᵀ f(P q) [N], resized to 3·#Q.
  void forces(ConstRef<VectorXd> q, VectorXd& f) const;
  /// K_q = Pᵀ K(P q) P in the fixed pattern `stiffness_pattern()` (set on first use).
  void stiffness(ConstRef<VectorXd> q, SparseMatrixd& K, bool project_psd) const;
  const SparseMatrixd& stiffness_pattern() const;
  /// Tets that touch a vertex with a weighted C row (they assemble through the mesh-level layer).
  Index num_layer_tets() const { return m_num_layer_tets; }

 private:
  /// One addition of the layer's scatter: K_q's values[target + i] += weight · layer value
  /// 3 · block + i, i = 0, 1, 2 (the weight C_va C_wb of the layer block (v, w) in K_q's block
  /// (a, b)).
  struct LayerAddition {
    int block;
    int target;
    double weight;
  };
  void build_reduced_pattern();

  const ElasticModel* m_model;
  bool m_identity = true;
  Index m_num_dof_vertices = 0;
  std::vector<int> m_dof_vertices;
  VectorXd m_rest_positions;
  double m_total_rest_volume = 0.0;
  double m_mean_edge_length = 0.0;
  SparseMatrixd m_C;
  SparseMatrixd m_CT;  ///< Cᵀ, for reductions
  SparseMatrixd m_pattern;
  /// For each tet in the mesh model's order (ElasticModel::sorted_tets): whether it is in the
  /// layer, and the 48 offsets of its element blocks in K_q's values or in the layer's.
  std::vector<std::uint8_t> m_in_layer;
  FillVector<int> m_offsets;
  Index m_num_layer_tets = 0;
  /// The additions of the layer's blocks (3-value columns, values 3g … 3g + 2 of block g) to
  /// K_q, by the DOF vertex b whose block column they add to: b's are [m_column_begin[b],
  /// m_column_begin[b + 1]) of m_layer_additions, and each value's come in the order of the
  /// layer's blocks.
  FillVector<LayerAddition> m_layer_additions;
  std::vector<Index> m_column_begin{0};
  Index m_num_layer_blocks = 0;
  mutable FillVector<double> m_layer_values;  ///< the layer's mesh-level blocks
};

}  // namespace strata
