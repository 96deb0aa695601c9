#pragma once
/// \file algebraic_multigrid.hpp
/// Algebraic multigrid for Newton systems of meshes without nested coarser spaces, from hypre's
/// BoomerAMG (Debian's libhypre, serial): its coarse spaces (prolongations(), which the linear
/// solver runs in the tree's multigrid cycle, multigrid.hpp) or its own V-cycle (apply()).
///
/// The systems are displacement DOFs: each row belongs to one component (x, y or z). The
/// hierarchy is built per component (the "unknown" approach: interpolation only between rows of
/// the same component), which keeps the rigid translations in every coarse space. When every
/// vertex of the system has all three rows (consecutive x, y, z), the coarsening is nodal: one
/// decision per vertex from the Frobenius norms of the 3 × 3 blocks, so a vertex's components
/// stay together; when any vertex has only some of its DOFs free, each component is coarsened on
/// its own.
/// Coarsening is HMIS with extended+i interpolation (at most 4 entries per row). hypre's own cycle
/// smooths by ℓ1 Gauss–Seidel, forward on the way down and backward on the way up, so it is
/// symmetric and can precondition CG; it runs on one thread (Debian builds hypre without OpenMP),
/// which is why the linear solver uses the coarse spaces with strata's threaded cycle instead.
///
/// hypre needs MPI: the first setup initialises it (a singleton process, no `mpirun`) unless the
/// host program already has, and finalises it at exit. Every hypre object lives on MPI_COMM_SELF,
/// so a host program's MPI ranks each build their own hierarchy.
#include <memory>
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct AlgebraicMultigridOptions {
  /// Strength threshold of the coarsening (hypre's default 0.25 suits 2D; 0.5 3D elasticity).
  double strong_threshold = 0.5;
  /// The DOF (3 × vertex + component) of each row, ascending; empty: rows 0, 1, …, every vertex
  /// whole (x, y, z, x, y, z, …).
  std::vector<Index> row_dofs;
};

class AlgebraicMultigrid {
 public:
  using Options = AlgebraicMultigridOptions;

  explicit AlgebraicMultigrid(Options options = Options());
  ~AlgebraicMultigrid();
  AlgebraicMultigrid(const AlgebraicMultigrid&) = delete;
  AlgebraicMultigrid& operator=(const AlgebraicMultigrid&) = delete;

  /// Builds the hierarchy of A (symmetric, both triangles stored, compressed; as many rows as
  /// `row_dofs` when that is given, else a multiple of 3; std::invalid_argument otherwise).
  /// Returns false if hypre reports an error. The matrix is copied.
  bool setup(const SparseMatrixd& A);
  /// z = one V-cycle applied to r (setup() first).
  void apply(ConstRef<VectorXd> r, VectorXd& z) const;

  int num_levels() const;
  /// The interpolations of the last setup as DOF prolongations, coarsest first (the last one's
  /// rows are A's): the input of MultigridPreconditioner.
  std::vector<SparseMatrixd> prolongations() const;
  double setup_seconds() const { return m_setup_seconds; }  ///< wall time of the last setup()

 private:
  struct Impl;
  Options m_options;
  std::unique_ptr<Impl> m_impl;
  double m_setup_seconds = 0.0;
};

}  // namespace strata
