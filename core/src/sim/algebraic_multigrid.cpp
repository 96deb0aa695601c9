#include "strata/core/sim/algebraic_multigrid.hpp"

// The C interface of MPI suffices (no C++ bindings to link).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h>  // hypre_ParAMGData: the number of levels
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace strata {
namespace {

static_assert(sizeof(HYPRE_Int) == sizeof(SparseMatrixd::StorageIndex) &&
                  sizeof(HYPRE_BigInt) == sizeof(SparseMatrixd::StorageIndex),
              "hypre's indices are Eigen's");
static_assert(sizeof(HYPRE_Real) == sizeof(double), "hypre's reals are doubles");

/// Serialises every hypre and MPI call of the process (MPI is initialised with
/// MPI_THREAD_SERIALIZED).
std::mutex& hypre_mutex() {
  static std::mutex mutex;
  return mutex;
}

bool g_finalize_mpi = false;

void finalize_hypre() {
  const std::lock_guard lock(hypre_mutex());
  HYPRE_Finalize();
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (g_finalize_mpi && finalized == 0) MPI_Finalize();
}

/// Initialises MPI (unless the host program has) and hypre once per process. Call with the mutex
/// held.
void ensure_hypre() {
  static bool ready = false;
  if (ready) return;
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized == 0) {
    // A singleton process needs no supporting daemon (Open MPI would otherwise start one).
    setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    int provided = 0;
    // Every MPI and hypre call is serialised by the mutex; hypre needs no more than that.
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
      throw std::runtime_error("algebraic multigrid: MPI could not be initialised");
    g_finalize_mpi = true;
  }
  HYPRE_Init();
  std::atexit(finalize_hypre);
  ready = true;
}

struct IjVector {
  HYPRE_IJVector ij = nullptr;
  HYPRE_ParVector par = nullptr;

  explicit IjVector(HYPRE_BigInt n) {
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &ij);
    HYPRE_IJVectorSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(ij);
    HYPRE_IJVectorAssemble(ij);
    HYPRE_IJVectorGetObject(ij, reinterpret_cast<void**>(&par));
  }
  ~IjVector() { HYPRE_IJVectorDestroy(ij); }
  IjVector(const IjVector&) = delete;
  IjVector& operator=(const IjVector&) = delete;
};

}  // namespace

struct AlgebraicMultigrid::Impl {
  HYPRE_IJMatrix matrix = nullptr;
  HYPRE_ParCSRMatrix par_matrix = nullptr;
  HYPRE_Solver amg = nullptr;
  std::unique_ptr<IjVector> rhs, solution;
  std::vector<HYPRE_BigInt> indices;  ///< 0, 1, …, n − 1
  int levels = 0;

  void release() {
    if (amg != nullptr) HYPRE_BoomerAMGDestroy(amg);
    if (matrix != nullptr) HYPRE_IJMatrixDestroy(matrix);
    amg = nullptr;
    matrix = nullptr;
    par_matrix = nullptr;
    rhs.reset();
    solution.reset();
    levels = 0;
  }
  ~Impl() {
    const std::lock_guard lock(hypre_mutex());
    release();
  }
};

AlgebraicMultigrid::AlgebraicMultigrid(Options options)
    : m_options(options), m_impl(std::make_unique<Impl>()) {}

AlgebraicMultigrid::~AlgebraicMultigrid() = default;

int AlgebraicMultigrid::num_levels() const {
  return m_impl->levels;
}

bool AlgebraicMultigrid::setup(const SparseMatrixd& A) {
  if (!A.isCompressed())
    throw std::invalid_argument("algebraic multigrid: the matrix must be compressed");
  const std::vector<Index>& dofs = m_options.row_dofs;
  if (A.rows() != A.cols() ||
      (dofs.empty() ? A.rows() % 3 != 0 : static_cast<Index>(dofs.size()) != A.rows()))
    throw std::invalid_argument(
        "algebraic multigrid: the matrix must be square with a DOF per "
        "row (or a multiple of 3 rows)");
  // Whole vertices (3v, 3v + 1, 3v + 2 in consecutive rows) throughout: nodal coarsening.
  bool whole_vertices = A.rows() % 3 == 0;
  for (std::size_t i = 0; whole_vertices && i < dofs.size(); ++i)
    whole_vertices = dofs[i] == 3 * (dofs[i - i % 3] / 3) + static_cast<Index>(i % 3);
  const auto start = std::chrono::steady_clock::now();
  const std::lock_guard lock(hypre_mutex());
  ensure_hypre();
  Impl& impl = *m_impl;
  impl.release();
  const auto n = static_cast<HYPRE_BigInt>(A.rows());
  impl.indices.resize(static_cast<std::size_t>(n));
  std::iota(impl.indices.begin(), impl.indices.end(), HYPRE_BigInt{0});

  // A is symmetric with both triangles stored: its columns are its rows (CSR = CSC).
  std::vector<HYPRE_Int> row_sizes(static_cast<std::size_t>(n));
  for (HYPRE_BigInt i = 0; i < n; ++i)
    row_sizes[i] = A.outerIndexPtr()[i + 1] - A.outerIndexPtr()[i];
  bool ok = HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &impl.matrix) == 0;
  ok = ok && HYPRE_IJMatrixSetObjectType(impl.matrix, HYPRE_PARCSR) == 0;
  ok = ok && HYPRE_IJMatrixSetRowSizes(impl.matrix, row_sizes.data()) == 0;
  ok = ok && HYPRE_IJMatrixInitialize(impl.matrix) == 0;
  ok = ok && HYPRE_IJMatrixSetValues(impl.matrix, static_cast<HYPRE_Int>(n), row_sizes.data(),
                                     impl.indices.data(), A.innerIndexPtr(), A.valuePtr()) == 0;
  ok = ok && HYPRE_IJMatrixAssemble(impl.matrix) == 0;
  ok = ok && HYPRE_IJMatrixGetObject(impl.matrix, reinterpret_cast<void**>(&impl.par_matrix)) == 0;
  if (!ok) {
    impl.release();
    HYPRE_ClearAllErrors();
    return false;
  }
  impl.rhs = std::make_unique<IjVector>(n);
  impl.solution = std::make_unique<IjVector>(n);

  HYPRE_BoomerAMGCreate(&impl.amg);
  HYPRE_BoomerAMGSetPrintLevel(impl.amg, 0);
  HYPRE_BoomerAMGSetMaxIter(impl.amg, 1);  // one V-cycle per application
  HYPRE_BoomerAMGSetTol(impl.amg, 0.0);
  HYPRE_BoomerAMGSetNumFunctions(impl.amg, 3);
  if (whole_vertices) {
    HYPRE_BoomerAMGSetNodal(impl.amg, 1);  // Frobenius norms of the vertices' 3 × 3 blocks
  } else {
    // Each row's component; hypre takes the array (and frees it with the solver).
    auto* dof_func = hypre_CTAlloc(HYPRE_Int, static_cast<std::size_t>(n), HYPRE_MEMORY_HOST);
    for (HYPRE_BigInt i = 0; i < n; ++i)
      dof_func[i] = static_cast<HYPRE_Int>(dofs[static_cast<std::size_t>(i)] % 3);
    HYPRE_BoomerAMGSetDofFunc(impl.amg, dof_func);
  }
  HYPRE_BoomerAMGSetStrongThreshold(impl.amg, m_options.strong_threshold);
  HYPRE_BoomerAMGSetCoarsenType(impl.amg, 10);  // HMIS
  HYPRE_BoomerAMGSetInterpType(impl.amg, 6);    // extended+i
  HYPRE_BoomerAMGSetPMaxElmts(impl.amg, 4);
  // ℓ1 Gauss–Seidel, forward on the way down and backward on the way up: a symmetric cycle.
  HYPRE_BoomerAMGSetCycleRelaxType(impl.amg, 13, 1);
  HYPRE_BoomerAMGSetCycleRelaxType(impl.amg, 14, 2);
  HYPRE_BoomerAMGSetCycleRelaxType(impl.amg, 9, 3);  // Gaussian elimination on the coarsest
  HYPRE_BoomerAMGSetNumSweeps(impl.amg, 1);
  ok = HYPRE_BoomerAMGSetup(impl.amg, impl.par_matrix, impl.rhs->par, impl.solution->par) == 0;
  if (!ok) {
    impl.release();
    HYPRE_ClearAllErrors();
    return false;
  }
  impl.levels = hypre_ParAMGDataNumLevels(reinterpret_cast<hypre_ParAMGData*>(impl.amg));
  m_setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return true;
}

std::vector<SparseMatrixd> AlgebraicMultigrid::prolongations() const {
  const std::lock_guard lock(hypre_mutex());
  std::vector<SparseMatrixd> result;
  if (m_impl->amg == nullptr) return result;
  auto* data = reinterpret_cast<hypre_ParAMGData*>(m_impl->amg);
  const int levels = hypre_ParAMGDataNumLevels(data);
  for (int level = levels - 2; level >= 0; --level) {  // coarsest first
    hypre_CSRMatrix* P = hypre_ParCSRMatrixDiag(hypre_ParAMGDataPArray(data)[level]);
    const HYPRE_Int rows = hypre_CSRMatrixNumRows(P);
    const HYPRE_Int cols = hypre_CSRMatrixNumCols(P);
    const HYPRE_Int* offsets = hypre_CSRMatrixI(P);
    std::vector<Eigen::Triplet<double, SparseMatrixd::StorageIndex>> entries;
    entries.reserve(static_cast<std::size_t>(offsets[rows]));
    for (HYPRE_Int i = 0; i < rows; ++i)
      for (HYPRE_Int k = offsets[i]; k < offsets[i + 1]; ++k)
        entries.emplace_back(i, hypre_CSRMatrixJ(P)[k], hypre_CSRMatrixData(P)[k]);
    SparseMatrixd prolongation(rows, cols);
    prolongation.setFromTriplets(entries.begin(), entries.end());
    result.push_back(std::move(prolongation));
  }
  return result;
}

void AlgebraicMultigrid::apply(ConstRef<VectorXd> r, VectorXd& z) const {
  Impl& impl = *m_impl;
  if (impl.amg == nullptr)
    throw std::logic_error("algebraic multigrid: apply() before a successful setup()");
  const auto n = static_cast<HYPRE_Int>(impl.indices.size());
  if (r.size() != n)
    throw std::invalid_argument("algebraic multigrid: apply() to a vector of another size");
  z.resize(r.size());
  const std::lock_guard lock(hypre_mutex());
  HYPRE_IJVectorSetValues(impl.rhs->ij, n, impl.indices.data(), r.data());
  HYPRE_ParVectorSetConstantValues(impl.solution->par, 0.0);
  HYPRE_BoomerAMGSolve(impl.amg, impl.par_matrix, impl.rhs->par, impl.solution->par);
  HYPRE_IJVectorGetValues(impl.solution->ij, n, impl.indices.data(), z.data());
  HYPRE_ClearAllErrors();  // a cycle that did not "converge" in its single iteration is expected
}

}  // namespace strata
