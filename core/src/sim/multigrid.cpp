#include "strata/core/sim/multigrid.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/common/vector_chunks.hpp"
#include "strata/core/sim/block_matrix.hpp"

namespace strata {

void NestedSpaces::check() const {
  if (injections.size() != prolongations.size())
    throw std::invalid_argument("NestedSpaces: one injection per prolongation expected");
  if (!keys.empty()) {
    if (keys.size() != prolongations.size())
      throw std::invalid_argument("NestedSpaces: one key list per coarse space expected");
    for (std::size_t k = 0; k < keys.size(); ++k)
      if (static_cast<Index>(keys[k].size()) != prolongations[k].cols())
        throw std::invalid_argument("NestedSpaces: key list " + std::to_string(k) +
                                    " has the wrong size");
  }
  for (std::size_t k = 0; k < prolongations.size(); ++k) {
    const SparseMatrixd& P = prolongations[k];
    if (k + 1 < prolongations.size() && prolongations[k + 1].cols() != P.rows())
      throw std::invalid_argument("NestedSpaces: sizes of prolongations " + std::to_string(k) +
                                  " and " + std::to_string(k + 1) + " do not chain");
    if (static_cast<Index>(injections[k].size()) != P.cols())
      throw std::invalid_argument("NestedSpaces: injection " + std::to_string(k) +
                                  " has the wrong size");
    std::vector<int> row_entries(P.rows(), 0);
    for (Index c = 0; c < P.outerSize(); ++c)
      for (SparseMatrixd::InnerIterator it(P, c); it; ++it)
        if (it.value() != 0.0) ++row_entries[it.row()];
    for (Index j = 0; j < P.cols(); ++j) {
      const Index i = injections[k][j];
      if (i < 0 || i >= P.rows() || P.coeff(i, j) != 1.0 || row_entries[i] != 1)
        throw std::invalid_argument("NestedSpaces: injection " + std::to_string(k) +
                                    " is not a unit row at coarse vertex " + std::to_string(j));
    }
  }
}

namespace {

/// The free index of each DOF of each space (−1: constrained), finest last.
std::vector<std::vector<Index>> free_indices(const NestedSpaces& spaces,
                                             const std::vector<Index>& free_dofs) {
  const int levels = spaces.num_levels();
  std::vector<std::vector<Index>> free_index(levels);
  const Index num_dofs = 3 * spaces.num_fine_vertices();
  free_index[levels - 1].assign(num_dofs, -1);
  for (std::size_t i = 0; i < free_dofs.size(); ++i) {
    if (free_dofs[i] < 0 || free_dofs[i] >= num_dofs || (i > 0 && free_dofs[i] <= free_dofs[i - 1]))
      throw std::invalid_argument("nested spaces: free DOF " + std::to_string(i) +
                                  " is not an ascending index below " + std::to_string(num_dofs));
    free_index[levels - 1][free_dofs[i]] = static_cast<Index>(i);
  }
  for (int k = levels - 2; k >= 0; --k) {
    const std::vector<Index>& injection = spaces.injections[k];
    std::vector<Index>& index = free_index[k];
    index.assign(3 * injection.size(), -1);
    Index next = 0;
    for (std::size_t j = 0; j < injection.size(); ++j)
      for (int c = 0; c < 3; ++c)
        if (free_index[k + 1][3 * injection[j] + c] >= 0) index[3 * j + c] = next++;
  }
  return free_index;
}

}  // namespace

std::vector<SparseMatrixd> free_dof_prolongations(const NestedSpaces& spaces,
                                                  const std::vector<Index>& free_dofs,
                                                  std::vector<std::vector<std::int64_t>>* keys) {
  std::vector<SparseMatrixd> result;
  if (keys != nullptr) keys->clear();
  if (spaces.empty()) return result;
  const int levels = spaces.num_levels();
  const std::vector<std::vector<Index>> free_index = free_indices(spaces, free_dofs);
  if (keys != nullptr && !spaces.keys.empty())
    for (int k = 0; k + 1 < levels; ++k) {
      std::vector<std::int64_t>& level_keys = keys->emplace_back();
      for (std::size_t j = 0; j < spaces.keys[k].size(); ++j)
        for (int c = 0; c < 3; ++c)
          if (free_index[k][3 * j + c] >= 0) level_keys.push_back(3 * spaces.keys[k][j] + c);
    }
  // Column 3j + c of P_k ⊗ I₃ holds the rows 3i + c of column j of P_k; restricted to the free
  // DOFs, both index maps are ascending, so each column is written in place in P_k's row order.
  for (int k = 0; k + 1 < levels; ++k) {
    const SparseMatrixd& P = spaces.prolongations[k];
    const std::vector<Index>& rows = free_index[k + 1];
    const std::vector<Index>& cols = free_index[k];
    const Index num_rows = std::count_if(rows.begin(), rows.end(), [](Index i) { return i >= 0; });
    const Index num_cols = std::count_if(cols.begin(), cols.end(), [](Index i) { return i >= 0; });
    SparseMatrixd D(num_rows, num_cols);
    int* outer = D.outerIndexPtr();
    outer[0] = 0;
    for (Index j = 0; j < P.outerSize(); ++j)
      for (int c = 0; c < 3; ++c) {
        const Index col = cols[3 * j + c];
        if (col < 0) continue;
        int count = 0;
        for (SparseMatrixd::InnerIterator it(P, j); it; ++it)
          count += rows[3 * it.row() + c] >= 0;
        outer[col + 1] = count;
      }
    for (Index col = 0; col < num_cols; ++col)
      outer[col + 1] += outer[col];
    D.resizeNonZeros(outer[num_cols]);
    int* inner = D.innerIndexPtr();
    double* values = D.valuePtr();
    tbb::parallel_for(Index(0), P.outerSize(), [&](Index j) {
      for (int c = 0; c < 3; ++c) {
        const Index col = cols[3 * j + c];
        if (col < 0) continue;
        Index position = outer[col];
        for (SparseMatrixd::InnerIterator it(P, j); it; ++it) {
          const Index row = rows[3 * it.row() + c];
          if (row < 0) continue;
          inner[position] = static_cast<int>(row);
          values[position++] = it.value();
        }
      }
    });
    result.push_back(std::move(D));
  }
  return result;
}

void symmetric_product(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y) {
  const Index n = A.cols();
  y.resize(n);
  const auto* outer = A.outerIndexPtr();
  const auto* inner = A.innerIndexPtr();
  const double* values = A.valuePtr();
  const double* xs = x.data();
  double* ys = y.data();
  // Four partial sums per column (independent add chains instead of one, whose latency bounded
  // the loop), combined in a fixed order: the result does not depend on the thread count.
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 4096), [&](const tbb::blocked_range<Index>& r) {
    for (Index j = r.begin(); j != r.end(); ++j) {
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
      auto p = outer[j];
      const auto end = outer[j + 1];
      for (; p + 4 <= end; p += 4) {
        s0 += values[p] * xs[inner[p]];
        s1 += values[p + 1] * xs[inner[p + 1]];
        s2 += values[p + 2] * xs[inner[p + 2]];
        s3 += values[p + 3] * xs[inner[p + 3]];
      }
      for (; p < end; ++p)
        s0 += values[p] * xs[inner[p]];
      ys[j] = (s0 + s1) + (s2 + s3);
    }
  });
}

double symmetric_product(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                         const std::function<double(Index, Index)>& after) {
  symmetric_product(A, x, y);
  return after ? sum_over_vector_chunks(y.size(), after) : 0.0;
}

namespace {

/// Consecutive columns of a compressed matrix, computed apart (one task each).
struct Fragment {
  std::vector<int> counts;  ///< entries per column
  std::vector<int> rows;
  std::vector<double> values;
};

/// The n × n matrix whose columns are those of `fragments`, in order.
SparseMatrixd joined(const std::vector<Fragment>& fragments, Index n) {
  Index nonzeros = 0;
  for (const Fragment& fragment : fragments)
    nonzeros += static_cast<Index>(fragment.rows.size());
  SparseMatrixd C(n, n);
  C.resizeNonZeros(nonzeros);
  auto* outer = C.outerIndexPtr();
  outer[0] = 0;
  Index column = 0, offset = 0;
  for (const Fragment& fragment : fragments) {
    for (const int count : fragment.counts) {
      outer[column + 1] = static_cast<int>(outer[column] + count);
      ++column;
    }
    std::copy(fragment.rows.begin(), fragment.rows.end(), C.innerIndexPtr() + offset);
    std::copy(fragment.values.begin(), fragment.values.end(), C.valuePtr() + offset);
    offset += static_cast<Index>(fragment.rows.size());
  }
  return C;
}

/// One thread's column of a Galerkin product being summed: the values by row, the column that
/// last wrote each row (mark) and the rows written for the current one (touched).
struct ColumnAccumulator {
  std::vector<double> value;
  std::vector<Index> mark;
  std::vector<int> touched;
};

/// A sparse matrix by vertices: the column lists of an nv × mv pattern, with the positions of
/// its entries in the scalar matrix it came from.
struct VertexColumns {
  std::vector<int> outer;  ///< mv + 1
  std::vector<int> rows;   ///< vertex row of each entry
  std::vector<int> at;     ///< the entry's (0, 0) value in the scalar matrix's values
};

/// P = P_v ⊗ I₃ — the three DOFs of each vertex prolonged alike, columns 3j + c holding rows
/// 3i + c with equal weights — as P_v's columns; nothing otherwise (a vertex with some but not
/// all DOFs constrained).
std::optional<VertexColumns> vertex_prolongation(const SparseMatrixd& P) {
  if (!P.isCompressed() || P.rows() % 3 != 0 || P.cols() % 3 != 0) return std::nullopt;
  const int* outer = P.outerIndexPtr();
  const int* inner = P.innerIndexPtr();
  const double* values = P.valuePtr();
  VertexColumns result;
  const Index mv = P.cols() / 3;
  result.outer.assign(mv + 1, 0);
  result.rows.reserve(P.nonZeros() / 3);
  result.at.reserve(P.nonZeros() / 3);
  for (Index j = 0; j < mv; ++j) {
    const int first = outer[3 * j];
    const int count = outer[3 * j + 1] - first;
    for (int c = 1; c < 3; ++c)
      if (outer[3 * j + c + 1] - outer[3 * j + c] != count) return std::nullopt;
    for (int k = 0; k < count; ++k) {
      const int row = inner[first + k];
      if (row % 3 != 0) return std::nullopt;
      for (int c = 1; c < 3; ++c) {
        const int other = outer[3 * j + c] + k;
        if (inner[other] != row + c || values[other] != values[first + k]) return std::nullopt;
      }
      result.rows.push_back(row / 3);
      result.at.push_back(first + k);
    }
    result.outer[j + 1] = static_cast<int>(result.rows.size());
  }
  return result;
}

/// PᵀAP by 3 × 3 blocks (P = P_v ⊗ I₃, A by its block copy): the same products added in the
/// same order as the scalar product below, entry by entry, so the result is bit for bit the same.
SparseMatrixd blocked_galerkin_product(const BlockSymmetricMatrix& A, const SparseMatrixd& P,
                                       const VertexColumns& Pv) {
  const Index nv = A.rows() / 3;
  const int* outer = A.block_outer();
  const int* block_rows = A.block_rows();
  const double* a_values = A.block_values();
  const Index mv = P.cols() / 3;
  const double* p_values = P.valuePtr();
  // P_v's rows: for each fine vertex a, the coarse vertices I and the positions of w_aI.
  VertexColumns rows_of;
  rows_of.outer.assign(nv + 1, 0);
  for (const int a : Pv.rows)
    ++rows_of.outer[a + 1];
  for (Index a = 0; a < nv; ++a)
    rows_of.outer[a + 1] += rows_of.outer[a];
  rows_of.rows.resize(Pv.rows.size());
  rows_of.at.resize(Pv.rows.size());
  {
    std::vector<int> next(rows_of.outer.begin(), rows_of.outer.end() - 1);
    for (Index J = 0; J < mv; ++J)
      for (int k = Pv.outer[J]; k < Pv.outer[J + 1]; ++k) {
        const int slot = next[Pv.rows[k]]++;
        rows_of.rows[slot] = static_cast<int>(J);
        rows_of.at[slot] = Pv.at[k];
      }
  }
  constexpr Index kBlock = 170;  // vertex columns per task (about 512 scalar columns)
  const Index num_blocks = (mv + kBlock - 1) / kBlock;
  std::vector<Fragment> fragments(num_blocks);
  // value: 9 per coarse vertex, (r, c) at 3c + r.
  tbb::enumerable_thread_specific<ColumnAccumulator> accumulators;
  tbb::parallel_for(Index(0), num_blocks, [&](Index block) {
    ColumnAccumulator& acc = accumulators.local();
    if (static_cast<Index>(acc.mark.size()) != mv) {
      acc.value.assign(9 * mv, 0.0);
      acc.mark.assign(mv, -1);
    }
    Fragment& fragment = fragments[block];
    const Index first = block * kBlock;
    const Index last = std::min(mv, first + kBlock);
    for (Index J = first; J < last; ++J) {
      acc.touched.clear();
      for (int p = Pv.outer[J]; p < Pv.outer[J + 1]; ++p) {
        const int b = Pv.rows[p];
        const double w_bJ = p_values[Pv.at[p]];
        for (int e = outer[b]; e < outer[b + 1]; ++e) {
          const int a = block_rows[e];
          double ap[9];  // A(3a + r, 3b + c) · w_bJ at 3c + r
          const double* block_ab = a_values + 9 * static_cast<Index>(e);
          for (int k = 0; k < 9; ++k)
            ap[k] = block_ab[k] * w_bJ;
          for (int q = rows_of.outer[a]; q < rows_of.outer[a + 1]; ++q) {
            const int I = rows_of.rows[q];
            const double w_aI = p_values[rows_of.at[q]];
            double* value = &acc.value[9 * static_cast<Index>(I)];
            if (acc.mark[I] != J) {
              acc.mark[I] = J;
              std::fill(value, value + 9, 0.0);
              acc.touched.push_back(I);
            }
            // w_aI · (A · w_bJ), as the scalar product forms it (the same rounding, and the same
            // contraction into fused multiply-adds): keep the two expressions alike.
            for (int k = 0; k < 9; ++k)
              value[k] += w_aI * ap[k];
          }
        }
      }
      std::sort(acc.touched.begin(), acc.touched.end());
      for (int c = 0; c < 3; ++c) {
        fragment.counts.push_back(3 * static_cast<int>(acc.touched.size()));
        for (const int I : acc.touched)
          for (int r = 0; r < 3; ++r) {
            fragment.rows.push_back(3 * I + r);
            fragment.values.push_back(acc.value[9 * static_cast<Index>(I) + 3 * c + r]);
          }
      }
    }
  });
  return joined(fragments, 3 * mv);
}

}  // namespace

namespace {

/// By blocks where `blocks` holds A and P = P_v ⊗ I₃; otherwise entry by entry.
SparseMatrixd blocked_or_scalar_product(const SparseMatrixd& A, const BlockSymmetricMatrix& blocks,
                                        const SparseMatrixd& P) {
  if (!blocks.empty() && blocks.rows() == A.rows() && A.rows() == P.rows())
    if (const std::optional<VertexColumns> Pv = vertex_prolongation(P))
      return blocked_galerkin_product(blocks, P, *Pv);
  return scalar_galerkin_product(A, P);
}

}  // namespace

bool galerkin_product_by_blocks(const SparseMatrixd& A, const SparseMatrixd& P) {
  return A.rows() == P.rows() && vertex_prolongation(P).has_value() &&
         BlockSymmetricMatrix().assign(A);
}

SparseMatrixd galerkin_product(const SparseMatrixd& A, const SparseMatrixd& P) {
  BlockSymmetricMatrix blocks;
  blocks.assign(A);  // holds nothing unless A is made of whole blocks
  return blocked_or_scalar_product(A, blocks, P);
}

SparseMatrixd galerkin_product(const SparseMatrixd& A, const BlockSymmetricMatrix& blocks,
                               const SparseMatrixd& P) {
  if (blocks.empty() || blocks.rows() != A.rows()) return galerkin_product(A, P);
  return blocked_or_scalar_product(A, blocks, P);
}

SparseMatrixd scalar_galerkin_product(const SparseMatrixd& A, const SparseMatrixd& P) {
  const Index m = P.cols();
  const SparseMatrixd PT = P.transpose();  // column i of PT = row i of P
  // Column blocks computed in parallel, each into its own compressed fragment.
  constexpr Index kBlock = 512;
  const Index num_blocks = (m + kBlock - 1) / kBlock;
  std::vector<Fragment> fragments(num_blocks);
  tbb::enumerable_thread_specific<ColumnAccumulator> accumulators;
  tbb::parallel_for(Index(0), num_blocks, [&](Index block) {
    ColumnAccumulator& acc = accumulators.local();
    if (static_cast<Index>(acc.value.size()) != m) {
      acc.value.assign(m, 0.0);
      acc.mark.assign(m, -1);
    }
    Fragment& fragment = fragments[block];
    const Index first = block * kBlock;
    const Index last = std::min(m, first + kBlock);
    for (Index J = first; J < last; ++J) {
      acc.touched.clear();
      for (SparseMatrixd::InnerIterator p(P, J); p; ++p)
        for (SparseMatrixd::InnerIterator a(A, p.row()); a; ++a) {
          const double ap = a.value() * p.value();
          for (SparseMatrixd::InnerIterator q(PT, a.row()); q; ++q) {
            const Index L = q.row();
            if (acc.mark[L] != J) {
              acc.mark[L] = J;
              acc.value[L] = 0.0;
              acc.touched.push_back(static_cast<int>(L));
            }
            acc.value[L] += q.value() * ap;
          }
        }
      std::sort(acc.touched.begin(), acc.touched.end());
      fragment.counts.push_back(static_cast<int>(acc.touched.size()));
      for (const int L : acc.touched) {
        fragment.rows.push_back(L);
        fragment.values.push_back(acc.value[L]);
      }
    }
  });
  return joined(fragments, m);
}

namespace {

/// The row-sum (Gershgorin) bound max_j Σ_i |A_ij| / A_jj of the spectrum of D⁻¹A (A symmetric,
/// both triangles stored), over ranges of columns in parallel (a maximum: the same at any thread
/// count). D⁻¹ is read from `inverse_in`, or, when `inverse_out` is given instead, written there
/// from the same pass (zero where a diagonal entry is missing or not positive).
double row_sum_bound(const SparseMatrixd& A, const VectorXd* inverse_in, VectorXd* inverse_out) {
  if (inverse_out != nullptr) inverse_out->resize(A.cols());
  return tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, A.outerSize(), 2048), 0.0,
      [&](const tbb::blocked_range<Index>& range, double bound) {
        for (Index j = range.begin(); j != range.end(); ++j) {
          double sum = 0.0, diagonal = 0.0;
          for (SparseMatrixd::InnerIterator it(A, j); it; ++it) {
            sum += std::abs(it.value());
            if (it.index() == j) diagonal = it.value();
          }
          double inverse = 0.0;
          if (inverse_out != nullptr) {
            inverse = diagonal > 0.0 ? 1.0 / diagonal : 0.0;
            (*inverse_out)[j] = inverse;
          } else {
            inverse = (*inverse_in)[j];
          }
          bound = std::max(bound, sum * inverse);
        }
        return bound;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace

struct MultigridPreconditioner::Level {
  SparseMatrixd owned;               ///< coarse Galerkin operator (empty on the finest level)
  const SparseMatrixd* A = nullptr;  ///< the operator of this level
  BlockSymmetricMatrix blocks;       ///< A by 3 × 3 blocks, where its pattern allows (products)
  VectorXd inverse_diagonal;
  double lambda_min = 0.0;  ///< Chebyshev interval of D⁻¹A
  double lambda_max = 0.0;
  double lambda_estimate = 0.0;            ///< the Lanczos estimate λ̂ (measured or seeded)
  Index estimate_rows = 0;                 ///< the unknowns of the level λ̂ was measured on
  mutable VectorXd r, d, d_next, z, x, b;  ///< scratch of the cycle
};

struct MultigridPreconditioner::Coarse {
  Eigen::CholmodSupernodalLLT<SparseMatrixd, Eigen::Lower> llt;
  bool analysed = false;
  Index nonzeros = -1;
};

struct MultigridCoarseLevels {
  /// Every level of the hierarchy they came from but the finest, coarsest first.
  std::vector<std::unique_ptr<MultigridPreconditioner::Level>> levels;
  std::unique_ptr<MultigridPreconditioner::Coarse> coarse;
  /// The prolongations between them (P_0 … P_{L−2}) and the keys of their unknowns.
  std::vector<SparseMatrixd> prolongations;
  std::vector<std::vector<std::int64_t>> keys;
  double iterations_per_decade = -1.0;
};

namespace {

/// The seed of smoothed level k (1 … L) of `rows` unknowns: seeds[k − 1] when there is one per
/// smoothed level, its estimate is positive and finite and it was measured on a level within a
/// factor 2 of this one's size; otherwise none (λ = 0: measure).
SmootherEstimate usable_seed(const std::vector<SmootherEstimate>& seeds, int L, int k, Index rows) {
  if (static_cast<int>(seeds.size()) != L) return {};
  const SmootherEstimate& seed = seeds[k - 1];
  if (seed.lambda > 0.0 && std::isfinite(seed.lambda) && seed.rows > 0 && 2 * seed.rows >= rows &&
      seed.rows <= 2 * rows)
    return seed;
  return {};
}

/// Whether two compressed matrices are the same entry for entry (pattern and values).
bool same_matrix(const SparseMatrixd& a, const SparseMatrixd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros() ||
      !a.isCompressed() || !b.isCompressed())
    return false;
  const auto n = static_cast<std::size_t>(a.nonZeros());
  return std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + n, b.innerIndexPtr()) &&
         std::equal(a.valuePtr(), a.valuePtr() + n, b.valuePtr());
}

}  // namespace

MultigridPreconditioner::MultigridPreconditioner(std::vector<SparseMatrixd> prolongations,
                                                 Options options,
                                                 std::vector<std::vector<std::int64_t>> coarse_keys)
    : m_options(options),
      m_prolongations(std::move(prolongations)),
      m_coarse(std::make_unique<Coarse>()),
      m_coarse_keys(std::move(coarse_keys)) {
  if (m_options.smoothing_degree < 1)
    throw std::invalid_argument("MultigridPreconditioner: smoothing_degree must be >= 1");
  for (std::size_t k = 0; k + 1 < m_prolongations.size(); ++k)
    if (m_prolongations[k + 1].cols() != m_prolongations[k].rows())
      throw std::invalid_argument("MultigridPreconditioner: prolongation sizes do not chain");
  if (!m_coarse_keys.empty()) {
    if (m_coarse_keys.size() != m_prolongations.size())
      throw std::invalid_argument(
          "MultigridPreconditioner: one key list per coarse level expected");
    for (std::size_t k = 0; k < m_coarse_keys.size(); ++k)
      if (static_cast<Index>(m_coarse_keys[k].size()) != m_prolongations[k].cols())
        throw std::invalid_argument("MultigridPreconditioner: key list " + std::to_string(k) +
                                    " has the wrong size");
  }
  for (const SparseMatrixd& P : m_prolongations)
    m_prolongation_rows.emplace_back(P);
  m_levels.resize(m_prolongations.size() + 1);
  for (auto& level : m_levels)
    level = std::make_unique<Level>();
  m_coarse->llt.cholmod().print = 0;
}

MultigridPreconditioner::~MultigridPreconditioner() = default;

std::vector<Index> MultigridPreconditioner::level_sizes() const {
  return m_sizes;
}

bool MultigridPreconditioner::setup(const SparseMatrixd& A) {
  const auto start = std::chrono::steady_clock::now();
  // A seed and offered levels serve this setup, whatever its outcome.
  const std::vector<SmootherEstimate> pending_seed = std::move(m_seed);
  m_seed.clear();
  const int L = num_levels() - 1;
  if (!m_prolongations.empty() && m_prolongations.back().rows() != A.rows())
    throw std::invalid_argument("MultigridPreconditioner::setup: matrix has " +
                                std::to_string(A.rows()) + " rows, the finest level " +
                                std::to_string(m_prolongations.back().rows()));
  m_sizes.clear();
  m_carried_setup = m_offered != nullptr;
  m_carried_iterations_per_decade = -1.0;
  if (m_carried_setup) {
    // The coarse levels are the offered ones (offer_coarse_levels checked that they fit): only
    // the finest level is set up.
    const std::unique_ptr<MultigridCoarseLevels> offered = std::move(m_offered);
    for (int k = 0; k < L; ++k)
      m_levels[k] = std::move(offered->levels[k]);
    m_coarse = std::move(offered->coarse);
    // The factor is the previous hierarchy's; a later setup of this one analyses its own pattern.
    m_coarse->analysed = false;
    m_carried_iterations_per_decade = offered->iterations_per_decade;
    Level& finest = *m_levels[L];
    finest.A = &A;
    finest.owned.resize(0, 0);
    finest.blocks.clear();
    finest.blocks.keep_single_precision(A.nonZeros() / 9 >= m_options.single_precision_min_blocks);
    finest.blocks.assign(A);
    const SmootherEstimate seed = usable_seed(pending_seed, L, L, A.rows());
    m_seeded_setup = seed.lambda > 0.0;
    setup_smoother(finest, seed);
    for (const auto& level : m_levels)
      m_sizes.push_back(level->A->rows());
    m_setup_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return m_coarse->llt.info() == Eigen::Success;
  }
  for (auto& level : m_levels)
    level->blocks.clear();  // copied anew below
  m_levels[L]->A = &A;
  m_levels[L]->owned.resize(0, 0);
  // Finest first: the block copy of each level whose operator multiplies vectors (the smoothed
  // ones and the finest, CG's; the large ones with a single-precision copy for the cycle's
  // products), then the next coarser operator from it.
  for (int k = L - 1; k >= 0; --k) {
    Level& fine = *m_levels[k + 1];
    fine.blocks.keep_single_precision(fine.A->nonZeros() / 9 >=
                                      m_options.single_precision_min_blocks);
    fine.blocks.assign(*fine.A);
    SparseMatrixd coarse = galerkin_product(*fine.A, fine.blocks, m_prolongations[k]);
    m_levels[k]->owned.swap(coarse);  // Eigen's assignment from a named matrix would copy it
    m_levels[k]->A = &m_levels[k]->owned;
  }
  if (L == 0) {
    m_levels[0]->blocks.keep_single_precision(false);
    m_levels[0]->blocks.assign(A);
  }
  m_seeded_setup = false;
  for (int k = 1; k <= L; ++k) {
    const SmootherEstimate seed = usable_seed(pending_seed, L, k, m_levels[k]->A->rows());
    m_seeded_setup = m_seeded_setup || seed.lambda > 0.0;
    setup_smoother(*m_levels[k], seed);
  }
  m_sizes.clear();
  for (const auto& level : m_levels)
    m_sizes.push_back(level->A->rows());
  const SparseMatrixd& A0 = *m_levels[0]->A;
  if (!m_coarse->analysed || m_coarse->nonzeros != A0.nonZeros()) {
    m_coarse->llt.analyzePattern(A0);
    m_coarse->analysed = true;
    m_coarse->nonzeros = A0.nonZeros();
  }
  m_coarse->llt.factorize(A0);
  m_setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m_coarse->llt.info() == Eigen::Success;
}

std::shared_ptr<MultigridCoarseLevels> MultigridPreconditioner::release_coarse_levels(
    double iterations_per_decade) {
  const int L = num_levels() - 1;
  if (m_sizes.empty() || L < 1 || m_coarse_keys.empty()) return nullptr;
  // What this hierarchy keeps, made before anything is moved.
  std::vector<std::unique_ptr<Level>> emptied(L);
  for (auto& level : emptied)
    level = std::make_unique<Level>();
  auto coarse = std::make_unique<Coarse>();
  coarse->llt.cholmod().print = 0;
  auto released = std::make_shared<MultigridCoarseLevels>();
  released->prolongations.assign(m_prolongations.begin(), m_prolongations.end() - 1);
  released->keys = m_coarse_keys;
  released->iterations_per_decade = iterations_per_decade;
  for (int k = 0; k < L; ++k) {
    released->levels.push_back(std::move(m_levels[k]));
    m_levels[k] = std::move(emptied[k]);
  }
  released->coarse = std::move(m_coarse);
  m_coarse = std::move(coarse);
  // Nothing is left to apply: setup() before the next use (update_finest() throws until then).
  m_sizes.clear();
  Level& finest = *m_levels[L];
  finest.A = nullptr;
  finest.blocks.clear();
  return released;
}

void MultigridPreconditioner::offer_coarse_levels(std::shared_ptr<MultigridCoarseLevels> levels) {
  m_offered.reset();
  if (levels == nullptr) return;
  auto taken = std::make_unique<MultigridCoarseLevels>(std::move(*levels));
  *levels = MultigridCoarseLevels();
  const int L = num_levels() - 1;
  if (L < 1 || m_coarse_keys.empty() || taken->coarse == nullptr ||
      static_cast<int>(taken->levels.size()) != L || taken->keys != m_coarse_keys ||
      static_cast<int>(taken->prolongations.size()) != L - 1)
    return;
  for (int k = 0; k + 1 < L; ++k)
    if (!same_matrix(taken->prolongations[k], m_prolongations[k])) return;
  m_offered = std::move(taken);
}

void MultigridPreconditioner::update_finest(const SparseMatrixd& A) {
  Level& finest = *m_levels.back();
  // The previous finest matrix may be gone: compare with the size recorded at setup.
  if (m_sizes.empty() || m_sizes.back() != A.rows())
    throw std::logic_error("MultigridPreconditioner::update_finest before setup or size change");
  finest.A = &A;
  finest.blocks.assign(A);
  if (num_levels() == 1) return;
  // The new diagonal; the eigenvalue estimate of the setup stays (nearby matrices; a smoother
  // that no longer fits shows as a failed or non-positive PCG solve, and the caller sets up anew).
  for_each_vector_chunk(A.rows(), [&](Index begin, Index end) {
    for (Index i = begin; i < end; ++i) {
      const double d = A.coeff(i, i);
      finest.inverse_diagonal[i] = d > 0.0 ? 1.0 / d : 0.0;
    }
  });
}

std::vector<SmootherEstimate> MultigridPreconditioner::smoother_estimates() const {
  std::vector<SmootherEstimate> estimates;
  if (m_sizes.empty()) return estimates;
  for (int k = 1; k < num_levels(); ++k)
    estimates.push_back({m_levels[k]->estimate_rows, m_levels[k]->lambda_estimate});
  return estimates;
}

void MultigridPreconditioner::seed_smoother_estimates(std::vector<SmootherEstimate> estimates) {
  m_seed = std::move(estimates);
}

void MultigridPreconditioner::setup_smoother(Level& level, const SmootherEstimate& seed) {
  const SparseMatrixd& A = *level.A;
  const double gershgorin = row_sum_bound(A, nullptr, &level.inverse_diagonal);
  if (seed.lambda > 0.0) {
    // Above the row-sum bound an estimate is certainly too high for this operator.
    set_smoother_interval(level, std::min(seed.lambda, gershgorin), gershgorin);
    level.estimate_rows = seed.rows;
    return;
  }
  const Index n = A.rows();
  // Largest eigenvalue of D⁻¹A by Lanczos through Jacobi-preconditioned CG (faster to converge
  // at the spectrum's ends than power iteration), from a fixed pseudo-random right-hand side.
  std::mt19937 random(12345u);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VectorXd r(n);
  for (Index i = 0; i < n; ++i)
    r[i] = uniform(random);
  VectorXd z = level.inverse_diagonal.cwiseProduct(r);
  VectorXd p = z, Ap(n);
  double rz = r.dot(z);
  std::vector<double> alphas, betas;
  for (int it = 0; it < m_options.lanczos_iterations && rz > 0.0; ++it) {
    multiply(level, p, Ap);
    const double curvature = p.dot(Ap);
    if (!(curvature > 0.0)) break;
    const double alpha = rz / curvature;
    r -= alpha * Ap;
    z = level.inverse_diagonal.cwiseProduct(r);
    const double rz_next = r.dot(z);
    const double beta = rz_next / rz;
    alphas.push_back(alpha);
    betas.push_back(beta);
    p = z + beta * p;
    rz = rz_next;
  }
  double lambda = 1.0;
  const int m = static_cast<int>(alphas.size());
  if (m > 0) {
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(m, m);
    for (int j = 0; j < m; ++j) {
      T(j, j) = 1.0 / alphas[j] + (j > 0 ? betas[j - 1] / alphas[j - 1] : 0.0);
      if (j + 1 < m) T(j, j + 1) = T(j + 1, j) = std::sqrt(betas[j]) / alphas[j];
    }
    lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly)
                 .eigenvalues()
                 .maxCoeff();
  }
  set_smoother_interval(level, lambda, gershgorin);
  level.estimate_rows = n;
}

void MultigridPreconditioner::set_smoother_interval(Level& level, double lambda,
                                                    double gershgorin) const {
  // A Ritz value bounds λ_max from below; the Chebyshev polynomial stays below 1 in magnitude
  // up to 2θ = upper + lower, so the upper end gets a margin, capped by the row-sum (Gershgorin)
  // bound of D⁻¹A, which holds for any matrix.
  level.lambda_estimate = lambda;
  level.lambda_max = std::min(1.2 * lambda, std::max(gershgorin, lambda));
  level.lambda_min = m_options.chebyshev_lower * lambda;
}

std::pair<double, double> MultigridPreconditioner::smoother_interval(int k) const {
  const Level& level = *m_levels.at(static_cast<std::size_t>(k));
  return {level.lambda_min, level.lambda_max};
}

bool MultigridPreconditioner::blocked_products(int k) const {
  return !m_levels.at(static_cast<std::size_t>(k))->blocks.empty();
}

bool MultigridPreconditioner::single_precision_products(int k) const {
  return m_levels.at(static_cast<std::size_t>(k))->blocks.has_single_precision();
}

void MultigridPreconditioner::widen_smoother_intervals() {
  for (int k = 1; k < num_levels(); ++k) {  // level 0 is solved directly
    Level& level = *m_levels[k];
    if (level.A != nullptr && level.inverse_diagonal.size() == level.A->rows())
      level.lambda_max =
          std::max(level.lambda_max, row_sum_bound(*level.A, &level.inverse_diagonal, nullptr));
  }
}

void MultigridPreconditioner::smooth(const Level& level, const VectorXd& b, VectorXd& x,
                                     bool zero_start) const {
  // Chebyshev iteration for A x = b preconditioned by D, started from x (Saad, Iterative
  // Methods for Sparse Linear Systems, Alg. 12.1), x = 0 when `zero_start` (x is then only
  // sized). Each product's rows are updated right after they are computed, on the same thread:
  // r −= A d, the next direction into d_next (d is still read by the product), x += d_next.
  const double theta = 0.5 * (level.lambda_max + level.lambda_min);
  const double delta = 0.5 * (level.lambda_max - level.lambda_min);
  const double sigma = theta / delta;
  const Index n = b.size();
  const VectorXd& D = level.inverse_diagonal;
  VectorXd& r = level.r;
  VectorXd& d = level.d;
  VectorXd& Ad = level.z;
  VectorXd& d_next = level.d_next;
  r.resize(n);
  d.resize(n);
  d_next.resize(n);
  if (zero_start)
    x.resize(n);
  else
    STRATA_VERIFY(x.size() == n, "MultigridPreconditioner::smooth: x has the wrong size");
  // The first direction d = D r / θ (x, when not zero, is read by its product and takes d with
  // the next update).
  const auto first_direction = [&](Index begin, Index end) {
    const Index m = end - begin;
    d.segment(begin, m) = D.segment(begin, m).cwiseProduct(r.segment(begin, m)) / theta;
    if (zero_start) x.segment(begin, m) = d.segment(begin, m);
    return 0.0;
  };
  if (zero_start) {
    for_each_vector_chunk(n, [&](Index begin, Index end) {
      r.segment(begin, end - begin) = b.segment(begin, end - begin);
      first_direction(begin, end);
    });
  } else {
    multiply(level, x, r, [&](Index begin, Index end) {
      r.segment(begin, end - begin) = b.segment(begin, end - begin) - r.segment(begin, end - begin);
      return first_direction(begin, end);
    });
  }
  bool d_in_x = zero_start;
  double rho = 1.0 / sigma;
  for (int i = 1; i < m_options.smoothing_degree; ++i) {
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    const double old_weight = rho_next * rho;
    const double new_weight = 2.0 * rho_next / delta;
    multiply(level, d, Ad, [&](Index begin, Index end) {
      const Index m = end - begin;
      if (!d_in_x) x.segment(begin, m) += d.segment(begin, m);
      r.segment(begin, m) -= Ad.segment(begin, m);
      d_next.segment(begin, m) = old_weight * d.segment(begin, m) +
                                 new_weight * D.segment(begin, m).cwiseProduct(r.segment(begin, m));
      x.segment(begin, m) += d_next.segment(begin, m);
      return 0.0;
    });
    d.swap(d_next);
    d_in_x = true;
    rho = rho_next;
  }
  if (!d_in_x)
    for_each_vector_chunk(n, [&](Index begin, Index end) {
      x.segment(begin, end - begin) += d.segment(begin, end - begin);
    });
}

void MultigridPreconditioner::cycle(int k, const VectorXd& b, VectorXd& x) const {
  if (k == 0) {
    x = m_coarse->llt.solve(b);
    return;
  }
  const Level& level = *m_levels[k];
  const Level& coarse = *m_levels[k - 1];
  const SparseMatrixd& P = m_prolongations[k - 1];
  const auto& P_rows = m_prolongation_rows[k - 1];
  smooth(level, b, x, true);
  // The residual r = b − A x, restricted by Pᵀ (column by column of P).
  multiply(level, x, level.r, [&](Index begin, Index end) {
    level.r.segment(begin, end - begin) =
        b.segment(begin, end - begin) - level.r.segment(begin, end - begin);
    return 0.0;
  });
  coarse.b.resize(P.cols());
  for_each_vector_chunk(P.cols(), [&](Index begin, Index end) {
    for (Index j = begin; j < end; ++j) {
      double sum = 0.0;
      for (SparseMatrixd::InnerIterator it(P, j); it; ++it)
        sum += it.value() * level.r[it.index()];
      coarse.b[j] = sum;
    }
  });
  cycle(k - 1, coarse.b, coarse.x);
  // The coarse correction x += P x_c, row by row.
  for_each_vector_chunk(P_rows.rows(), [&](Index begin, Index end) {
    for (Index i = begin; i < end; ++i) {
      double sum = 0.0;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor, int>::InnerIterator it(P_rows, i); it; ++it)
        sum += it.value() * coarse.x[it.index()];
      x[i] += sum;
    }
  });
  smooth(level, b, x, false);
}

double MultigridPreconditioner::multiply(const Level& level, ConstRef<VectorXd> x, VectorXd& y,
                                         const std::function<double(Index, Index)>& after) {
  if (level.blocks.has_single_precision()) return level.blocks.multiply_single(x, y, after);
  if (!level.blocks.empty()) return level.blocks.multiply(x, y, after);
  return symmetric_product(*level.A, x, y, after);
}

void MultigridPreconditioner::multiply_finest(const SparseMatrixd& A, ConstRef<VectorXd> x,
                                              VectorXd& y) const {
  multiply_finest(A, x, y, {});
}

double MultigridPreconditioner::multiply_finest(
    const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
    const std::function<double(Index, Index)>& after) const {
  const Level& finest = *m_levels.back();
  if (&A == finest.A && !finest.blocks.empty()) return finest.blocks.multiply(x, y, after);
  return symmetric_product(A, x, y, after);
}

void MultigridPreconditioner::apply(ConstRef<VectorXd> r, VectorXd& z) const {
  const Level& finest = *m_levels.back();
  if (finest.A == nullptr) throw std::logic_error("MultigridPreconditioner::apply before setup");
  finest.b = r;
  cycle(num_levels() - 1, finest.b, z);
}

}  // namespace strata
