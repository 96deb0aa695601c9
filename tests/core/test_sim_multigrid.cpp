// The multigrid building blocks (multigrid.hpp) against independent computations: the parallel
// Galerkin product against Eigen's sparse products, the parallel symmetric product against a
// dense one, the DOF prolongations against P ⊗ I₃ restricted by hand, and the V-cycle is a
// symmetric positive definite operator (what CG needs).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include "strata/core/common/parallel.hpp"
#include "strata/core/sim/block_matrix.hpp"
#include "strata/core/sim/multigrid.hpp"

namespace strata {
namespace {

/// A random sparse SPD matrix (both triangles): a random symmetric pattern plus a dominant
/// diagonal.
SparseMatrixd random_spd(Index n, int per_column, std::mt19937& random) {
  std::uniform_int_distribution<Index> index(0, n - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index j = 0; j < n; ++j) {
    triplets.emplace_back(j, j, 2.0 * per_column + 1.0);
    for (int k = 0; k < per_column; ++k) {
      const Index i = index(random);
      const double v = value(random);
      triplets.emplace_back(i, j, v);
      triplets.emplace_back(j, i, v);
    }
  }
  SparseMatrixd A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  return A;
}

/// A random prolongation-like matrix: every fine row has 1–3 non-negative weights.
SparseMatrixd random_prolongation(Index fine, Index coarse, std::mt19937& random) {
  std::uniform_int_distribution<Index> index(0, coarse - 1);
  std::uniform_int_distribution<int> count(1, 3);
  std::uniform_real_distribution<double> weight(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index i = 0; i < fine; ++i) {
    const int c = count(random);
    for (int k = 0; k < c; ++k)
      triplets.emplace_back(i, index(random), weight(random));
  }
  for (Index j = 0; j < coarse; ++j)
    triplets.emplace_back(j, j, 1.0);  // no empty column
  SparseMatrixd P(fine, coarse);
  P.setFromTriplets(triplets.begin(), triplets.end());
  return P;
}

/// S ⊗ B: each entry of S times the 3 × 3 block B (whole 3 × 3 blocks, as stiffness matrices).
SparseMatrixd kron3(const SparseMatrixd& S, const Eigen::Matrix3d& B) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index j = 0; j < S.outerSize(); ++j)
    for (SparseMatrixd::InnerIterator it(S, j); it; ++it)
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
          triplets.emplace_back(3 * it.row() + r, 3 * j + c, it.value() * B(r, c));
  SparseMatrixd K(3 * S.rows(), 3 * S.cols());
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

TEST(Multigrid, GalerkinProductMatchesEigen) {
  std::mt19937 random(7u);
  for (const Index n : {Index(50), Index(3000)}) {
    const SparseMatrixd A = random_spd(n, 6, random);
    const SparseMatrixd P = random_prolongation(n, n / 5, random);
    const SparseMatrixd expected = SparseMatrixd(P.transpose()) * (A * P);
    const SparseMatrixd C = galerkin_product(A, P);
    ASSERT_EQ(C.rows(), P.cols());
    ASSERT_EQ(C.cols(), P.cols());
    EXPECT_LE((Eigen::MatrixXd(C) - Eigen::MatrixXd(expected)).cwiseAbs().maxCoeff(),
              1e-12 * Eigen::MatrixXd(expected).cwiseAbs().maxCoeff());
    for (Index j = 0; j < C.outerSize(); ++j)  // rows sorted within each column
      for (auto p = C.outerIndexPtr()[j] + 1; p < C.outerIndexPtr()[j + 1]; ++p)
        EXPECT_LT(C.innerIndexPtr()[p - 1], C.innerIndexPtr()[p]);
  }
}

/// The bits of a sparse matrix: its pattern and values.
bool same_bits(const SparseMatrixd& a, const SparseMatrixd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a.nonZeros() == b.nonZeros() &&
         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr()) &&
         std::memcmp(a.valuePtr(), b.valuePtr(), sizeof(double) * a.nonZeros()) == 0;
}

TEST(Multigrid, GalerkinProductByVertexBlocksIsTheScalarOneBitForBit) {
  // A by whole 3 × 3 blocks (blocks that differ, as a stiffness has) and P = P_v ⊗ I₃: the
  // blocked product adds the scalar one's products in its order. A P with one DOF dropped (a
  // vertex fixed in x only) or a pattern of partial blocks goes entry by entry; all agree with
  // Eigen's product.
  std::mt19937 random(17u);
  for (const Index nv : {Index(40), Index(2500)}) {
    const SparseMatrixd S = random_spd(nv, 5, random);
    std::vector<Eigen::Triplet<double>> triplets;
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    for (Index j = 0; j < S.outerSize(); ++j)
      for (SparseMatrixd::InnerIterator it(S, j); it; ++it) {
        if (it.row() > j) continue;
        Eigen::Matrix3d B = Eigen::Matrix3d::NullaryExpr([&] { return value(random); });
        if (it.row() == j) B = B * B.transpose() + 3.0 * Eigen::Matrix3d::Identity();
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            triplets.emplace_back(3 * it.row() + r, 3 * j + c, it.value() * B(r, c));
            if (it.row() != j)
              triplets.emplace_back(3 * j + c, 3 * it.row() + r, it.value() * B(r, c));
          }
      }
    SparseMatrixd A(3 * nv, 3 * nv);
    A.setFromTriplets(triplets.begin(), triplets.end());
    const SparseMatrixd Pv = random_prolongation(nv, nv / 5, random);
    std::vector<Eigen::Triplet<double>> weights;  // P_v ⊗ I₃ without the zeros off the diagonal
    for (Index j = 0; j < Pv.outerSize(); ++j)
      for (SparseMatrixd::InnerIterator it(Pv, j); it; ++it)
        for (int c = 0; c < 3; ++c)
          weights.emplace_back(3 * it.row() + c, 3 * j + c, it.value());
    SparseMatrixd P(3 * Pv.rows(), 3 * Pv.cols());
    P.setFromTriplets(weights.begin(), weights.end());
    ASSERT_TRUE(galerkin_product_by_blocks(A, P));
    const SparseMatrixd blocked = galerkin_product(A, P);
    const SparseMatrixd scalar = scalar_galerkin_product(A, P);
    EXPECT_TRUE(same_bits(blocked, scalar)) << nv;
    // From A's block copy (the values nine by nine), the same bits; with P not by vertices, or
    // no copy, the scalar product's.
    BlockSymmetricMatrix copy;
    ASSERT_TRUE(copy.assign(A));
    EXPECT_TRUE(same_bits(galerkin_product(A, copy, P), scalar)) << nv;
    EXPECT_TRUE(same_bits(galerkin_product(A, BlockSymmetricMatrix(), P), scalar)) << nv;
    const SparseMatrixd expected = SparseMatrixd(P.transpose()) * (A * P);
    EXPECT_LE((Eigen::MatrixXd(blocked) - Eigen::MatrixXd(expected)).cwiseAbs().maxCoeff(),
              1e-12 * Eigen::MatrixXd(expected).cwiseAbs().maxCoeff());
    // One fine DOF dropped (a vertex fixed in x only): rows of P no longer come in triples.
    std::vector<Eigen::Triplet<double>> kept;
    for (Index j = 0; j < P.outerSize(); ++j)
      for (SparseMatrixd::InnerIterator it(P, j); it; ++it)
        if (it.row() != 3) kept.emplace_back(it.row() < 3 ? it.row() : it.row() - 1, j, it.value());
    SparseMatrixd P_dropped(P.rows() - 1, P.cols());
    P_dropped.setFromTriplets(kept.begin(), kept.end());
    SparseMatrixd A_dropped(A.rows() - 1, A.cols() - 1);
    {
      std::vector<Eigen::Triplet<double>> entries;
      for (Index j = 0; j < A.outerSize(); ++j)
        for (SparseMatrixd::InnerIterator it(A, j); it; ++it)
          if (it.row() != 3 && j != 3)
            entries.emplace_back(it.row() < 3 ? it.row() : it.row() - 1, j < 3 ? j : j - 1,
                                 it.value());
      A_dropped.setFromTriplets(entries.begin(), entries.end());
    }
    EXPECT_FALSE(galerkin_product_by_blocks(A_dropped, P_dropped));
    // Sizes that are multiples of 3 whose structure is not by vertices: one weight that differs
    // between a vertex's components; A with an entry of an off-diagonal block removed; A with a
    // stored zero in a block (still whole blocks: by blocks, and the same bits).
    SparseMatrixd P_uneven = P;
    P_uneven.valuePtr()[P_uneven.outerIndexPtr()[1]] *= 1.5;  // column 1: component y of vertex 0
    EXPECT_FALSE(galerkin_product_by_blocks(A, P_uneven));
    EXPECT_TRUE(same_bits(galerkin_product(A, P_uneven), scalar_galerkin_product(A, P_uneven)));
    EXPECT_TRUE(
        same_bits(galerkin_product(A, copy, P_uneven), scalar_galerkin_product(A, P_uneven)));
    SparseMatrixd A_partial = A;  // entries (y of a, z of b) of off-diagonal blocks removed
    A_partial.prune([](Index row, Index col, double) {
      return !(row / 3 != col / 3 && row % 3 == 1 && col % 3 == 2);
    });
    EXPECT_FALSE(galerkin_product_by_blocks(A_partial, P));
    EXPECT_TRUE(same_bits(galerkin_product(A_partial, P), scalar_galerkin_product(A_partial, P)));
    BlockSymmetricMatrix partial_copy;  // a copy that failed holds nothing: entry by entry
    EXPECT_FALSE(partial_copy.assign(A_partial));
    EXPECT_TRUE(same_bits(galerkin_product(A_partial, partial_copy, P),
                          scalar_galerkin_product(A_partial, P)));
    SparseMatrixd A_zero = A;
    A_zero.valuePtr()[A_zero.outerIndexPtr()[4] + 1] = 0.0;  // stored, not removed
    EXPECT_TRUE(galerkin_product_by_blocks(A_zero, P));
    EXPECT_TRUE(same_bits(galerkin_product(A_zero, P), scalar_galerkin_product(A_zero, P)));
    BlockSymmetricMatrix zero_copy;
    ASSERT_TRUE(zero_copy.assign(A_zero));
    EXPECT_TRUE(
        same_bits(galerkin_product(A_zero, zero_copy, P), scalar_galerkin_product(A_zero, P)));
    EXPECT_FALSE(galerkin_product_by_blocks(A, kron3(Pv, Eigen::Matrix3d::Identity())));  // zeros
    const SparseMatrixd C = galerkin_product(A_dropped, P_dropped);
    // A copy of another size (A's, not A_dropped's) is not read.
    EXPECT_TRUE(same_bits(galerkin_product(A_dropped, copy, P_dropped), C));
    const SparseMatrixd expected_dropped =
        SparseMatrixd(P_dropped.transpose()) * (A_dropped * P_dropped);
    EXPECT_TRUE(same_bits(C, scalar_galerkin_product(A_dropped, P_dropped)));
    EXPECT_LE((Eigen::MatrixXd(C) - Eigen::MatrixXd(expected_dropped)).cwiseAbs().maxCoeff(),
              1e-12 * Eigen::MatrixXd(expected_dropped).cwiseAbs().maxCoeff());
  }
}

TEST(Multigrid, SymmetricProductMatchesDense) {
  std::mt19937 random(11u);
  const SparseMatrixd A = random_spd(20000, 8, random);
  VectorXd x = VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  VectorXd y;
  symmetric_product(A, x, y);
  const VectorXd expected = A * x;
  EXPECT_LE((y - expected).lpNorm<Eigen::Infinity>(), 1e-12 * expected.lpNorm<Eigen::Infinity>());
}

TEST(Multigrid, FreeDofProlongationsDropConstrainedDofs) {
  // Two coarse vertices, three fine ones (the midpoint between them); vertex 0's x is fixed.
  NestedSpaces spaces;
  SparseMatrixd P(3, 2);
  std::vector<Eigen::Triplet<double>> t{{0, 0, 1.0}, {1, 1, 1.0}, {2, 0, 0.5}, {2, 1, 0.5}};
  P.setFromTriplets(t.begin(), t.end());
  spaces.prolongations = {P};
  spaces.injections = {{0, 1}};
  spaces.check();
  std::vector<Index> free;
  for (Index i = 1; i < 9; ++i)
    free.push_back(i);  // DOF 0 (vertex 0, x) constrained
  const std::vector<SparseMatrixd> dof = free_dof_prolongations(spaces, free);
  ASSERT_EQ(dof.size(), 1u);
  ASSERT_EQ(dof[0].rows(), 8);
  ASSERT_EQ(dof[0].cols(), 5);  // the coarse x DOF of vertex 0 is dropped too
  // Expected: (P ⊗ I₃) without row 0 and column 0.
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(9, 6);
  for (int c = 0; c < 3; ++c)
    for (const auto& e : t)
      full(3 * e.row() + c, 3 * e.col() + c) = e.value();
  EXPECT_EQ((Eigen::MatrixXd(dof[0]) - full.bottomRightCorner(8, 5)).cwiseAbs().maxCoeff(), 0.0);
  // Stored as Eigen stores it from triplets: the same columns, rows in the same order.
  const SparseMatrixd expected = full.bottomRightCorner(8, 5).sparseView();
  ASSERT_EQ(dof[0].nonZeros(), expected.nonZeros());
  EXPECT_TRUE(
      std::equal(expected.outerIndexPtr(), expected.outerIndexPtr() + 6, dof[0].outerIndexPtr()));
  EXPECT_TRUE(std::equal(expected.innerIndexPtr(), expected.innerIndexPtr() + expected.nonZeros(),
                         dof[0].innerIndexPtr()));
}

TEST(Multigrid, FinestProductsFollowTheOperatorInUse) {
  // Per coordinate: a scalar prolongation and SPD matrix, each taken ⊗ a 3 × 3 factor.
  std::mt19937 random(9u);
  const SparseMatrixd P = kron3(random_prolongation(300, 60, random), Eigen::Matrix3d::Identity());
  Eigen::Matrix3d B;
  B << 2.0, 0.5, 0.0, 0.5, 2.0, 0.5, 0.0, 0.5, 2.0;  // SPD, with stored zeros in every block
  const SparseMatrixd blocked = kron3(random_spd(300, 4, random), B);
  const SparseMatrixd scalar = random_spd(900, 6, random);  // no whole blocks
  // CG's products stay in double when the cycle's are rounded (single_precision_min_blocks 0).
  MultigridOptions single;
  single.single_precision_min_blocks = 0;
  for (const SparseMatrixd* A : {&blocked, &scalar})
    for (const MultigridOptions& options : {MultigridOptions(), single}) {
      MultigridPreconditioner mg({P}, options);
      ASSERT_TRUE(mg.setup(*A));
      EXPECT_EQ(mg.single_precision_products(1),
                A == &blocked && options.single_precision_min_blocks == 0);
      const VectorXd x = VectorXd::Random(900);
      const VectorXd Ax = *A * x;
      VectorXd y;
      mg.multiply_finest(*A, x, y);
      EXPECT_LE((y - Ax).norm(), 1e-13 * Ax.norm());
      // update_finest: the products follow the new operator.
      const SparseMatrixd doubled = 2.0 * *A;
      mg.update_finest(doubled);
      mg.multiply_finest(doubled, x, y);
      EXPECT_LE((y - 2.0 * Ax).norm(), 1e-13 * Ax.norm());
      // A matrix other than the finest operator is multiplied as it is.
      const SparseMatrixd tripled = 3.0 * *A;
      mg.multiply_finest(tripled, x, y);
      EXPECT_LE((y - 3.0 * Ax).norm(), 1e-13 * Ax.norm());
    }
}

/// Prolongations of three levels, 80 → 400 → 2000 unknowns.
std::vector<SparseMatrixd> three_levels(std::mt19937& random) {
  std::vector<SparseMatrixd> prolongations;
  prolongations.push_back(random_prolongation(400, 80, random));
  prolongations.push_back(random_prolongation(2000, 400, random));
  return prolongations;
}

/// r₂ᵀ M r₁ = r₁ᵀ M r₂ and r₁ᵀ M r₁ > 0 for the V-cycle M on five pairs of random vectors.
void expect_symmetric_positive_definite(const MultigridPreconditioner& mg, Index n,
                                        std::mt19937& random) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    VectorXd r1(n), r2(n), z1, z2;
    for (Index i = 0; i < n; ++i) {
      r1[i] = value(random);
      r2[i] = value(random);
    }
    mg.apply(r1, z1);
    mg.apply(r2, z2);
    EXPECT_NEAR(r2.dot(z1), r1.dot(z2), 1e-10 * r1.norm() * z2.norm());
    EXPECT_GT(r1.dot(z1), 0.0);
  }
}

TEST(Multigrid, VCycleIsSymmetricPositiveDefinite) {
  std::mt19937 random(3u);
  const SparseMatrixd A = random_spd(2000, 6, random);
  const std::vector<SparseMatrixd> prolongations = three_levels(random);
  MultigridPreconditioner mg(prolongations);
  ASSERT_TRUE(mg.setup(A));
  EXPECT_EQ(mg.level_sizes(), (std::vector<Index>{80, 400, 2000}));
  expect_symmetric_positive_definite(mg, A.rows(), random);
}

TEST(Multigrid, WideningTheSmoothersMakesAnIndefiniteCyclePositiveDefinite) {
  // One Lanczos step estimates the top of D⁻¹A's spectrum from a random vector: near its middle,
  // so the smoothers' Chebyshev interval misses the top and the V-cycle is indefinite along the
  // top eigenvector. Widening the intervals to the row-sum bound makes it definite again.
  std::mt19937 random(5u);
  const SparseMatrixd A = random_spd(2000, 6, random);
  const std::vector<SparseMatrixd> prolongations = three_levels(random);
  MultigridOptions options;
  options.lanczos_iterations = 1;
  MultigridPreconditioner mg(prolongations, options);
  ASSERT_TRUE(mg.setup(A));
  // The top eigenvector of D⁻¹A by power iteration.
  const VectorXd diagonal = A.diagonal();
  VectorXd v = VectorXd::Ones(A.rows());
  for (int it = 0; it < 500; ++it) {
    v = (A * v).cwiseQuotient(diagonal);
    v /= v.norm();
  }
  const VectorXd r = A * v;
  VectorXd z;
  mg.apply(r, z);
  ASSERT_LT(r.dot(z), 0.0) << "the cycle of one Lanczos step is not indefinite here";
  mg.widen_smoother_intervals();
  mg.apply(r, z);
  EXPECT_GT(r.dot(z), 0.0);
  expect_symmetric_positive_definite(mg, A.rows(), random);
}

TEST(Multigrid, ACoarseSpaceOfEverythingMakesTheCycleExact) {
  // With P = I the coarse correction solves the residual left by the pre-smoother exactly, and
  // the post-smoother, started from the solution, keeps it: z = A⁻¹ r to round-off. This checks
  // the residual, the restriction, the correction and the post-smoother's start against a dense
  // solve.
  std::mt19937 random(13u);
  const Index n = 3000;
  const SparseMatrixd A = random_spd(n, 5, random);
  SparseMatrixd identity(n, n);
  identity.setIdentity();
  MultigridPreconditioner mg({identity});
  ASSERT_TRUE(mg.setup(A));
  const VectorXd r = VectorXd::Random(n);
  VectorXd z;
  mg.apply(r, z);
  const VectorXd exact = Eigen::MatrixXd(A).ldlt().solve(r);
  EXPECT_LE((z - exact).norm(), 1e-10 * exact.norm());
}

/// The V-cycle written out serially with Eigen's own products (the textbook form the
/// preconditioner implements): Galerkin operators PᵀAP, a dense solve on the coarsest level,
/// `degree` Chebyshev steps in D⁻¹A on each level's interval (Saad, Alg. 12.1) before and after
/// the coarse correction.
class ReferenceCycle {
 public:
  /// `rounded`: the smoothers' and residuals' products by the operators' values rounded to
  /// single precision (MultigridOptions::single_precision_min_blocks); the Galerkin products, the
  /// diagonals and the coarsest solve by the operators themselves.
  ReferenceCycle(const SparseMatrixd& A, const std::vector<SparseMatrixd>& P,
                 const MultigridPreconditioner& mg, int degree, bool rounded = false)
      : m_P(P), m_degree(degree) {
    m_A.resize(P.size() + 1);
    m_A.back() = A;
    for (int k = static_cast<int>(P.size()) - 1; k >= 0; --k)
      m_A[k] = SparseMatrixd(P[k].transpose() * m_A[k + 1] * P[k]);
    m_product_A = m_A;
    if (rounded)
      for (SparseMatrixd& product : m_product_A)
        product = SparseMatrixd(product.cast<float>().cast<double>());
    for (std::size_t k = 1; k < m_A.size(); ++k)
      m_interval.push_back(mg.smoother_interval(static_cast<int>(k)));
    m_coarse = Eigen::MatrixXd(m_A[0]).ldlt();
  }
  VectorXd apply(const VectorXd& b) const { return cycle(static_cast<int>(m_P.size()), b); }

 private:
  void smooth(int k, const VectorXd& b, VectorXd& x) const {
    const SparseMatrixd& A = m_product_A[k];
    const VectorXd inverse_diagonal = m_A[k].diagonal().cwiseInverse();
    const auto [lambda_min, lambda_max] = m_interval[k - 1];
    const double theta = 0.5 * (lambda_max + lambda_min);
    const double delta = 0.5 * (lambda_max - lambda_min);
    const double sigma = theta / delta;
    VectorXd r = b - A * x;
    VectorXd d = inverse_diagonal.cwiseProduct(r) / theta;
    double rho = 1.0 / sigma;
    for (int i = 0; i < m_degree; ++i) {
      x += d;
      if (i + 1 == m_degree) break;
      r -= A * d;
      const double rho_next = 1.0 / (2.0 * sigma - rho);
      d = (rho_next * rho) * d + (2.0 * rho_next / delta) * inverse_diagonal.cwiseProduct(r);
      rho = rho_next;
    }
  }
  VectorXd cycle(int k, const VectorXd& b) const {
    if (k == 0) return m_coarse.solve(b);
    VectorXd x = VectorXd::Zero(b.size());
    smooth(k, b, x);
    const VectorXd coarse = cycle(k - 1, m_P[k - 1].transpose() * (b - m_product_A[k] * x));
    x += m_P[k - 1] * coarse;
    smooth(k, b, x);
    return x;
  }

  std::vector<SparseMatrixd> m_A, m_product_A;
  std::vector<SparseMatrixd> m_P;
  std::vector<std::pair<double, double>> m_interval;
  Eigen::LDLT<Eigen::MatrixXd> m_coarse;
  int m_degree;
};

/// A three-level problem in two forms: scalar (random SPD A, random P, no whole blocks) and
/// blocked (A ⊗ B and P ⊗ I₃, whole 3 × 3 blocks on every level, the fused block products).
struct TwoForms {
  std::vector<SparseMatrixd> scalar_P, blocked_P;
  SparseMatrixd scalar_A, blocked_A;
  TwoForms(Index coarse, Index middle, Index fine, std::mt19937& random) {
    Eigen::Matrix3d B;
    B << 2.0, 0.5, 0.0, 0.5, 2.0, 0.5, 0.0, 0.5, 2.0;
    scalar_P = {random_prolongation(middle, coarse, random),
                random_prolongation(fine, middle, random)};
    scalar_A = random_spd(fine, 6, random);
    for (const SparseMatrixd& P : scalar_P)
      blocked_P.push_back(kron3(P, Eigen::Matrix3d::Identity()));
    blocked_A = kron3(scalar_A, B);
  }
  const SparseMatrixd& A(bool blocked) const { return blocked ? blocked_A : scalar_A; }
  const std::vector<SparseMatrixd>& P(bool blocked) const { return blocked ? blocked_P : scalar_P; }
};

TEST(Multigrid, CycleIsTheTextbookVCycle) {
  // Against the serial reference above, for smoothing degrees 1–3, on blocked operators (the
  // fused block products, every level; in double and rounded to single precision) and on scalar
  // ones (the compressed-column products, always double), with levels large enough for several
  // chunks.
  std::mt19937 random(19u);
  const TwoForms problem(60, 300, 2400, random);
  for (const bool blocked : {true, false}) {
    const SparseMatrixd& A = problem.A(blocked);
    const std::vector<SparseMatrixd>& P = problem.P(blocked);
    for (const bool single : {false, true}) {
      for (const int degree : {1, 2, 3}) {
        SCOPED_TRACE(std::string(blocked ? "blocked" : "scalar") + (single ? ", single" : "") +
                     ", degree " + std::to_string(degree));
        MultigridOptions options;
        options.smoothing_degree = degree;
        options.single_precision_min_blocks = single ? 0 : std::numeric_limits<Index>::max();
        MultigridPreconditioner mg(P, options);
        ASSERT_TRUE(mg.setup(A));
        const bool rounded = single && blocked;
        for (int k = 1; k < mg.num_levels(); ++k) {
          EXPECT_EQ(mg.blocked_products(k), blocked) << "level " << k;
          EXPECT_EQ(mg.single_precision_products(k), rounded) << "level " << k;
        }
        const ReferenceCycle reference(A, P, mg, degree, rounded);
        const VectorXd r = VectorXd::Random(A.rows());
        VectorXd z;
        mg.apply(r, z);
        const VectorXd expected = reference.apply(r);
        EXPECT_LE((z - expected).norm(), 1e-10 * expected.norm());
        // The rounding is seen: the cycle of the unrounded operators differs by more than the
        // tolerance above (by 3e-9 to 8e-9 here).
        if (rounded) {
          EXPECT_GT((z - ReferenceCycle(A, P, mg, degree).apply(r)).norm(), 1e-9 * expected.norm());
        }
      }
    }
  }
}

TEST(Multigrid, CycleDoesNotDependOnTheThreadCount) {
  // Levels large enough for many chunks, blocked (fused products) and scalar.
  std::mt19937 random(17u);
  const TwoForms problem(300, 1400, 10000, random);
  for (const bool blocked : {true, false}) {
    const SparseMatrixd& A = problem.A(blocked);
    MultigridPreconditioner mg(problem.P(blocked));
    ASSERT_TRUE(mg.setup(A));
    EXPECT_EQ(mg.blocked_products(mg.num_levels() - 1), blocked);
    const VectorXd r = VectorXd::Random(A.rows());
    VectorXd one, two;
    set_thread_policy({.threads = 1});
    mg.apply(r, one);
    set_thread_policy({.threads = 2});
    mg.apply(r, two);
    set_thread_policy({});
    EXPECT_EQ(one, two) << (blocked ? "blocked" : "scalar");
    EXPECT_GT(r.dot(one), 0.0);
  }
}

}  // namespace
}  // namespace strata
