#pragma once
/// \file elastic_model.hpp
/// Mesh level: elastic energy Ψ(x) = Σ_t V_t ψ(F_t), forces −∂Ψ/∂x and stiffness ∂²Ψ/∂x² of a
/// tet mesh, evaluated in parallel (TBB) over rest data precomputed in contiguous arrays.
///
/// Positions are 3·#V vertex-major vectors (see types.hpp). The stiffness matrix has a fixed
/// sparsity pattern, built on first use; `stiffness` only rewrites its values.
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "strata/core/common/fill_vector.hpp"
#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/fem/tet_partition.hpp"
#include "strata/core/fem/tet_rest_data.hpp"

namespace strata {

/// Where `ElasticModel::stiffness_into` puts each tet's element stiffness. For tet i in the
/// kernels' order (`sorted_tets()`), `offsets[48 i + 12 b + 3 a + c]` is the position of the entry
/// (row 3a, column 3b + c) of the element's 12 × 12 matrix for local vertices a, b; rows 3a + 1 and
/// 3a + 2 follow it (the twelve offsets of local vertex b's columns lie together). The positions
/// are in `values`, or in `second_values` for the tets with `in_second[i]` set (`in_second` may be
/// null). Tets that share no vertex must have disjoint targets: the tets of one colour of the
/// schedule are written concurrently.
struct StiffnessScatter {
  double* values = nullptr;
  const int* offsets = nullptr;
  const std::uint8_t* in_second = nullptr;
  double* second_values = nullptr;
};

/// Per-tet stress and strain measures for output.
struct TetFields {
  Eigen::Matrix<double, Eigen::Dynamic, 6> green_strain;   ///< #T × 6 Voigt [xx yy zz xy yz xz]
  Eigen::Matrix<double, Eigen::Dynamic, 6> cauchy_stress;  ///< #T × 6 Voigt [Pa]
  VectorXd von_mises;                                      ///< #T [Pa]
};

class ElasticModel {
 public:
  /// `tets` must be positively oriented and non-degenerate (throws InputError otherwise).
  ElasticModel(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX4i> tets,
               const Material& material);
  ~ElasticModel();

  Index num_vertices() const { return m_num_vertices; }
  Index num_tets() const { return m_tets.rows(); }
  Index num_dofs() const { return 3 * m_num_vertices; }
  const MatrixX4i& tets() const { return m_tets; }
  const Material& material() const { return m_material; }
  const TetRestData& rest_data() const { return m_rest; }
  /// Rest positions as a 3·#V vector.
  const VectorXd& rest_positions() const { return m_rest_positions; }

  /// Ψ(x) [J].
  double energy(ConstRef<VectorXd> x) const;
  /// f = −∂Ψ/∂x [N], resized to 3·#V and overwritten.
  void forces(ConstRef<VectorXd> x, VectorXd& f) const;
  /// Both at once; returns Ψ(x).
  double energy_and_forces(ConstRef<VectorXd> x, VectorXd& f) const;
  /// forces(x, f) and, from the same pass, min_volume_ratio(x) (J as det F of each tet, equal to
  /// det(Ds) det(Dm⁻¹) up to round-off).
  std::pair<double, Index> forces_and_min_volume_ratio(ConstRef<VectorXd> x, VectorXd& f) const;
  /// K = ∂²Ψ/∂x² in the fixed pattern of `stiffness_pattern()`; `K` is set to that pattern on the
  /// first call and only its values are rewritten afterwards. With `project_psd`, each element's
  /// ∂²ψ/∂F² is projected to PSD first (in closed form, see isotropic_hessian.hpp).
  void stiffness(ConstRef<VectorXd> x, SparseMatrixd& K, bool project_psd) const;
  /// The stiffness sparsity pattern (values zero), column-major, 3·#V square. Built on the first
  /// call (thread-safe, also from inside TBB tasks).
  const SparseMatrixd& stiffness_pattern() const;
  /// Adds every tet's element stiffness at x to the targets of `scatter` (see StiffnessScatter),
  /// on the same parallel schedule and with the same kernels as `stiffness`.
  void stiffness_into(ConstRef<VectorXd> x, bool project_psd,
                      const StiffnessScatter& scatter) const;
  /// The tets in the order of the kernels' schedule, 4 vertex indices each (see StiffnessScatter).
  const std::vector<int>& sorted_tets() const { return m_sorted_tets; }

  /// Smallest J = det F over the tets and the index of that tet (a NaN counts as smallest; ties
  /// go to the smaller index). Parallel.
  std::pair<double, Index> min_volume_ratio(ConstRef<VectorXd> x) const;
  /// Green strain of the total F, and the Cauchy and von Mises stress of the elastic part
  /// Fₑ = F Fₚ⁻¹, per tet.
  TetFields tet_fields(ConstRef<VectorXd> x) const;
  /// The Green strain of the total F per tet (#T × 6 Voigt), as in tet_fields, without the
  /// stresses. Parallel.
  Eigen::Matrix<double, Eigen::Dynamic, 6> green_strains(ConstRef<VectorXd> x) const;

  /// Plastic deformation per tet (plasticity.hpp): every tet's energy becomes V ψ(F Fₚ⁻¹), i.e.
  /// Dm⁻¹ is replaced by Dm⁻¹ Fₚ⁻¹ in every kernel. `plastic_inverse`: Fₚ⁻¹ per tet (#T, each with
  /// det 1 up to round-off); empty: Fₚ = I everywhere. Not thread-safe against concurrent
  /// evaluations.
  void set_plastic_inverse(const std::vector<Matrix3d>& plastic_inverse);
  /// Fₚ⁻¹ per tet; empty while Fₚ = I everywhere.
  const std::vector<Matrix3d>& plastic_inverse() const { return m_plastic_inverse; }

  /// Element evaluations so far (each tet visited by energy/forces/stiffness counts once).
  long long element_evaluations() const { return m_element_evaluations.load(); }

 private:
  template <typename Kernel>
  void accumulate_forces(const Kernel& kernel, ConstRef<VectorXd> x, VectorXd& f, double* energy,
                         std::pair<double, Index>* smallest_volume_ratio) const;
  void build_stiffness_pattern() const;
  /// Writes the kernels' rest arrays from Dm⁻¹ (and Fₚ⁻¹ if set).
  void fill_rest_arrays();

  Index m_num_vertices;
  MatrixX4i m_tets;
  Material m_material;
  LameParameters m_lame;
  TetRestData m_rest;
  VectorXd m_rest_positions;
  /// Parallel schedule; the arrays below are in its sorted tet order.
  TetPartition m_partition;
  std::vector<int> m_sorted_tets;          ///< 4 per tet
  FillVector<double> m_sorted_Dm_inv;      ///< 9 per tet, column-major
  FillVector<double> m_sorted_volume;      ///< 1 per tet
  FillVector<double> m_sorted_Dm_inv_det;  ///< det Dm⁻¹, 1 per tet
  /// Dm⁻¹ and rest volume in lane groups for the vectorised kernels, kLaneRest per group.
  static constexpr int kLaneRest = 40;
  std::vector<double> m_lane_rest;
  std::vector<Matrix3d> m_plastic_inverse;  ///< #T in mesh order, or empty
  struct PatternOnce;  ///< the once-flag of the pattern's construction (TBB-aware)
  std::unique_ptr<PatternOnce> m_pattern_once;
  mutable SparseMatrixd m_pattern;
  /// For sorted tet i, vertex pair (a, b) and column c: offset in K's value array of the entry
  /// (3·v_a, 3·v_b + c); rows 3·v_a + 1 and 3·v_a + 2 follow it. 48 per tet.
  mutable std::vector<int> m_block_offsets;
  mutable std::atomic<long long> m_element_evaluations{0};
};

}  // namespace strata
