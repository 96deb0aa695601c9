#pragma once
/// \file multigrid.hpp
/// Geometric multigrid for the Newton systems of a mesh that comes with nested coarser spaces (the
/// refinement tree's levels, hierarchy/cut_levels.hpp): a V-cycle used as the preconditioner of
/// conjugate gradients.
///
/// Spaces and transfers: `NestedSpaces` holds scalar prolongations P_k (space k → space k+1,
/// coarsest first; the last one maps onto the model's DOF vertices). A coarse function's values at
/// the finer vertices are its interpolant (for a tree: 1 at a vertex the spaces share, ½·½ along
/// a refined edge, hanging vertices through their constraints), so the coarse spaces are
/// subspaces of the fine one. For the 3-DOF-per-vertex Newton systems each P_k acts per
/// coordinate (P_k ⊗ I₃) and is restricted to the free DOFs: a coarse vertex's DOF is free where
/// the same vertex's DOF is free on the finest level (Dirichlet DOFs take no correction).
///
/// Cycle (one code path for every cut): coarse operators are Galerkin products A_k = P_kᵀ A_{k+1}
/// P_k, the coarsest is factorised (CHOLMOD), and every finer level is smoothed by a Chebyshev
/// polynomial in D⁻¹A (degree `smoothing_degree` before and after the coarse correction, on
/// [0.05 λ̂, min(1.2 λ̂, G)] with λ̂ the largest eigenvalue of D⁻¹A estimated by 12 Lanczos steps and
/// G its row-sum bound). The same polynomial before and after and an exact coarse solve make the
/// V-cycle symmetric; it is positive definite when A is and the smoother reduces every mode, i.e.
/// when λ_max(D⁻¹A) < 1.25 λ̂ (the polynomial's bound). The Lanczos estimate is within a few
/// per cent in practice; a cycle that is not positive definite shows as rᵀz ≤ 0 in PCG, which sets
/// up anew. Matrix–vector products and the smoothers run on TBB threads.
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

class BlockSymmetricMatrix;

/// Nested scalar spaces below a mesh's DOF vertices, coarsest first.
struct NestedSpaces {
  /// prolongations[k]: (#vertices of space k+1) × (#vertices of space k); the last one's rows are
  /// the DOF vertices of the model (3 DOFs each, vertex-major).
  std::vector<SparseMatrixd> prolongations;
  /// injections[k][j]: the vertex of space k+1 that coarse vertex j of space k is (its row of
  /// prolongations[k] is the unit row e_j).
  std::vector<std::vector<Index>> injections;
  /// keys[k][j]: what coarse vertex j of space k is, in terms that outlast this mesh (for the
  /// tree's levels: its tree vertex), so that a hierarchy built on the next mesh knows its coarse
  /// spaces for the same ones (MultigridPreconditioner::offer_coarse_levels). Empty: no keys, and
  /// no coarse levels are passed on.
  std::vector<std::vector<std::int64_t>> keys;

  bool empty() const { return prolongations.empty(); }
  /// Number of spaces including the finest (0 when empty).
  int num_levels() const { return empty() ? 0 : static_cast<int>(prolongations.size()) + 1; }
  /// Vertices of the finest space (the model's DOF vertices).
  Index num_fine_vertices() const { return empty() ? 0 : prolongations.back().rows(); }
  /// Throws std::invalid_argument unless sizes chain, every injection is a unit row and the keys,
  /// when given, are one per coarse vertex.
  void check() const;
};

/// The DOF prolongations (P_k ⊗ I₃ restricted to free DOFs, coarsest first) of `spaces` for a
/// system whose free DOFs are `free_dofs` (ascending indices into 3 · spaces.num_fine_vertices()).
/// With `keys`, also the keys of the free DOFs of each coarse space (coarsest first;
/// 3 · vertex key + coordinate, in the order of the prolongations' columns), empty when `spaces`
/// has no keys.
std::vector<SparseMatrixd> free_dof_prolongations(
    const NestedSpaces& spaces, const std::vector<Index>& free_dofs,
    std::vector<std::vector<std::int64_t>>* keys = nullptr);

/// y = A x for a symmetric A stored with both triangles (column-major), in parallel over columns.
void symmetric_product(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y);
/// The same, then `after(begin, end)` on y's rows by the chunks of vector_chunks.hpp (in
/// parallel); returns the sum of its values in chunk order (0 for an empty `after`).
double symmetric_product(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                         const std::function<double(Index, Index)>& after);

struct MultigridOptions {
  int smoothing_degree = 3;     ///< Chebyshev degree of the pre- and post-smoother
  int lanczos_iterations = 12;  ///< for the largest eigenvalue of D⁻¹A per level
  /// Chebyshev interval [chebyshev_lower · λ̂, min(1.2 λ̂, row-sum bound)] of D⁻¹A (λ̂: the
  /// Lanczos estimate).
  double chebyshev_lower = 0.05;
  /// The cycle's products (smoothers, residuals, the Lanczos estimate) on each level of at least
  /// this many 3 × 3 blocks use a copy of its values rounded to single precision, which reads 40
  /// bytes per block instead of 76; vectors and sums stay in double, and so do the products of
  /// multiply_finest (CG's). The smoothers and residuals then use the rounded operators, the
  /// Galerkin products, diagonals and coarsest factor the operators themselves: a symmetric
  /// preconditioner as before. On smaller levels the rounded copy measured slower than the
  /// double one (`strata_benchmarks --benchmark_filter=block_product`). 0: every blocked level;
  /// std::numeric_limits<Index>::max(): none.
  Index single_precision_min_blocks = 400000;
};

/// PᵀAP for a symmetric A (both triangles, column-major), computed column by column in parallel
/// (no intermediate A P); the result has both triangles, rows sorted in each column. When P
/// prolongs each vertex's three DOFs alike (P = P_v ⊗ I₃) and A's pattern is made of whole 3 × 3
/// vertex blocks, by blocks from a block copy of A (BlockSymmetricMatrix); otherwise entry by
/// entry (scalar_galerkin_product). Both add the same products in the same order: the results are
/// the same bit for bit.
SparseMatrixd galerkin_product(const SparseMatrixd& A, const SparseMatrixd& P);
/// The same from `blocks`, a block copy already made of A (BlockSymmetricMatrix::assign(A) with
/// A's current values: a copy of another matrix of A's size would be read as A). An empty copy or
/// one of another size is not read.
SparseMatrixd galerkin_product(const SparseMatrixd& A, const BlockSymmetricMatrix& blocks,
                               const SparseMatrixd& P);
SparseMatrixd scalar_galerkin_product(const SparseMatrixd& A, const SparseMatrixd& P);
/// Whether galerkin_product(A, P) goes by blocks.
bool galerkin_product_by_blocks(const SparseMatrixd& A, const SparseMatrixd& P);

/// The Lanczos estimate λ̂ of λ_max(D⁻¹A) on one smoothed level and that level's unknowns: what a
/// hierarchy on a nearby system (the previous cut of an adaptive run) can pass on to the next.
struct SmootherEstimate {
  Index rows = 0;
  double lambda = 0.0;
};

/// The coarse levels of a tree multigrid's setup — operators, smoothers and coarsest factor, with
/// the keys of their unknowns — passed on to a hierarchy built next on a nearby system
/// (MultigridPreconditioner::release_coarse_levels, offer_coarse_levels). Defined in the source.
struct MultigridCoarseLevels;

class MultigridPreconditioner {
 public:
  using Options = MultigridOptions;

  /// `prolongations`: DOF prolongations, coarsest first (see free_dof_prolongations); the last
  /// one's rows are the unknowns of the systems to precondition.
  /// `coarse_keys`: the keys of each coarse level's unknowns (free_dof_prolongations), coarsest
  /// first; empty: none (the hierarchy neither passes on nor takes coarse levels).
  explicit MultigridPreconditioner(std::vector<SparseMatrixd> prolongations,
                                   Options options = Options(),
                                   std::vector<std::vector<std::int64_t>> coarse_keys = {});
  ~MultigridPreconditioner();
  MultigridPreconditioner(const MultigridPreconditioner&) = delete;
  MultigridPreconditioner& operator=(const MultigridPreconditioner&) = delete;

  /// Galerkin coarse operators of A (symmetric, both triangles), coarsest factorisation and
  /// smoothers. Returns false if the coarsest operator is not numerically positive definite.
  /// A must outlive every later apply(): a pointer to it is kept, and where its pattern has whole
  /// 3 × 3 blocks a copy of its values for the products, so A's values must not change before
  /// the next setup() or update_finest().
  bool setup(const SparseMatrixd& A);
  /// Replaces the finest operator by A (same size; kept as setup() keeps it) and its smoother's
  /// diagonal; the coarse levels and the eigenvalue estimate of the last setup() stay (a
  /// preconditioner for nearby matrices).
  void update_finest(const SparseMatrixd& A);
  /// z = one V-cycle applied to r.
  void apply(ConstRef<VectorXd> r, VectorXd& z) const;
  /// y = A x. When A is the finest operator of the last setup() or update_finest(), by the
  /// 3 × 3-block copy those made of it where its pattern has whole blocks (BlockSymmetricMatrix);
  /// otherwise by symmetric_product.
  void multiply_finest(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y) const;
  /// The same, then `after(begin, end)` on fixed ranges of rows of y, in parallel (see
  /// BlockSymmetricMatrix::multiply); returns the sum of its values in range order.
  double multiply_finest(const SparseMatrixd& A, ConstRef<VectorXd> x, VectorXd& y,
                         const std::function<double(Index, Index)>& after) const;
  /// Every level's Chebyshev interval up to the row-sum (Gershgorin) bound of D⁻¹A, which holds
  /// for any matrix: for when a Lanczos estimate missed the top of a spectrum (a V-cycle that PCG
  /// finds indefinite). The smoothers then damp the whole spectrum and the cycle is positive
  /// definite, at slower smoothing, until the next setup().
  void widen_smoother_intervals();

  /// The Lanczos estimates of the smoothed levels (1 … finest) as of the last setup(), each with
  /// the unknowns of the level it was measured on (for a seeded level, the seed's).
  std::vector<SmootherEstimate> smoother_estimates() const;
  /// The next setup() — whether it succeeds or not — takes these as the Lanczos estimates of its
  /// smoothed levels (level 1 first) instead of running Lanczos, when their number is the number
  /// of smoothed levels, on each level whose unknowns are within a factor 2 of the estimate's
  /// (levels are matched by position; the tree's cuts number theirs alike) and whose estimate is
  /// positive and finite, at most the level's row-sum bound; the other levels run Lanczos.
  /// λ_max(D⁻¹A) of a level follows its elements' shapes and material, which a local change of
  /// the system leaves as they were; an estimate that misses the top of the new spectrum leaves
  /// the V-cycle indefinite, which widen_smoother_intervals repairs, as for a measured one.
  void seed_smoother_estimates(std::vector<SmootherEstimate> estimates);
  /// Whether the last setup() took a seeded estimate on any level.
  bool seeded_setup() const { return m_seeded_setup; }

  /// Gives up the coarse levels of the last setup() (every level but the finest, and the
  /// coarsest factor) for a hierarchy built next on a nearby system, with `iterations_per_decade`
  /// (the caller's measure of this hierarchy's PCG rate when it was fresh, −1: none) stored with
  /// them. This hierarchy then needs setup() before its next use. Null before a setup, with a
  /// single level or without coarse keys.
  std::shared_ptr<MultigridCoarseLevels> release_coarse_levels(double iterations_per_decade = -1.0);
  /// Offers `levels` (release_coarse_levels of a previous hierarchy, built with the same options)
  /// to the next setup(). Where this hierarchy's coarse levels have unknowns of the same keys in
  /// the same order and the same prolongations between them, they are kept for it: setup() then
  /// sets up only the finest level (its block copy and smoother; the Galerkin operator below it
  /// stays the previous system's, as the coarse levels stay after update_finest()). Otherwise they
  /// are dropped now, and setup() computes its own. Either way `levels` is left empty: one
  /// hierarchy takes them.
  void offer_coarse_levels(std::shared_ptr<MultigridCoarseLevels> levels);
  /// Whether the last setup() took offered coarse levels, and the rate stored with them.
  bool carried_setup() const { return m_carried_setup; }
  double carried_iterations_per_decade() const { return m_carried_iterations_per_decade; }

  int num_levels() const { return static_cast<int>(m_levels.size()); }
  /// The Chebyshev interval [λ_min, λ_max] of level k's smoother (D⁻¹A; k ≥ 1) and whether its
  /// products use the 3 × 3-block copy, as of the last setup (for tests and diagnostics).
  std::pair<double, double> smoother_interval(int k) const;
  bool blocked_products(int k) const;
  /// Whether level k's cycle products use single-precision values (single_precision_min_blocks).
  bool single_precision_products(int k) const;
  /// Unknowns per level, coarsest first.
  std::vector<Index> level_sizes() const;
  double setup_seconds() const { return m_setup_seconds; }  ///< wall time of the last setup()

 private:
  struct Level;
  struct Coarse;
  /// D⁻¹, the Lanczos estimate (or the seed's, when it has one) and the Chebyshev interval.
  void setup_smoother(Level& level, const SmootherEstimate& seed);
  /// [chebyshev_lower · λ̂, min(1.2 λ̂, max(row-sum bound, λ̂))] for the estimate λ̂.
  void set_smoother_interval(Level& level, double lambda, double gershgorin) const;
  void cycle(int k, const VectorXd& b, VectorXd& x) const;
  void smooth(const Level& level, const VectorXd& b, VectorXd& x, bool zero_start) const;
  static double multiply(const Level& level, ConstRef<VectorXd> x, VectorXd& y,
                         const std::function<double(Index, Index)>& after = {});

  Options m_options;
  std::vector<SparseMatrixd> m_prolongations;
  /// The prolongations by rows, for the coarse corrections' products in parallel.
  std::vector<Eigen::SparseMatrix<double, Eigen::RowMajor, int>> m_prolongation_rows;
  std::vector<std::unique_ptr<Level>> m_levels;  ///< coarsest first; finest last
  std::unique_ptr<Coarse> m_coarse;
  std::vector<Index> m_sizes;            ///< unknowns per level at the last setup
  std::vector<SmootherEstimate> m_seed;  ///< for the next setup (seed_smoother_estimates)
  bool m_seeded_setup = false;
  std::vector<std::vector<std::int64_t>> m_coarse_keys;  ///< per coarse level, coarsest first
  /// Offered coarse levels that fit this hierarchy, for the next setup (offer_coarse_levels).
  std::unique_ptr<MultigridCoarseLevels> m_offered;
  bool m_carried_setup = false;
  double m_carried_iterations_per_decade = -1.0;
  double m_setup_seconds = 0.0;

  friend struct MultigridCoarseLevels;
};

}  // namespace strata
