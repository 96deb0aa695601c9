#include "strata/core/sim/stable_time_step.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "strata/core/fem/deformation_gradient.hpp"

namespace strata {

double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material) {
  const LameParameters lame = material.lame();
  // The largest over all tets (exact in any order, so in parallel).
  const double max_gradient_eigenvalue = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, tets.rows(), 1024), 0.0,
      [&](const tbb::blocked_range<Index>& range, double largest) {
        for (Index t = range.begin(); t != range.end(); ++t) {
          Matrix3x4d x;
          for (int k = 0; k < 4; ++k)
            x.col(k) = positions.row(tets(t, k)).transpose();
          const Matrix3d Dm = edge_matrix(x);
          if (!(std::abs(Dm.determinant()) > 0.0))
            continue;  // degenerate tets are rejected earlier
          const Eigen::Matrix<double, 4, 3> G = shape_function_gradients(Dm.inverse());
          const Matrix3d GGt = G.transpose() * G;
          largest =
              std::max(largest, Eigen::SelfAdjointEigenSolver<Matrix3d>(GGt, Eigen::EigenvaluesOnly)
                                    .eigenvalues()
                                    .maxCoeff());
        }
        return largest;
      },
      [](double a, double b) { return std::max(a, b); });
  return std::sqrt(4.0 * (3.0 * lame.lambda + 2.0 * lame.mu) * max_gradient_eigenvalue /
                   material.density);
}

double explicit_stability_interval(Integrator integrator) {
  return integrator == Integrator::rk4 ? 2.0 * std::sqrt(2.0) : 2.0;
}

double stable_time_step_estimate(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 const Material& material, Integrator integrator) {
  return explicit_stability_interval(integrator) /
         max_angular_frequency_bound(positions, tets, material);
}

double mean_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets) {
  // Partial sums over fixed blocks of tets, added in block order: the same value for every
  // number of threads.
  const Index num_tets = tets.rows();
  if (num_tets == 0) return 0.0;
  constexpr Index kBlock = 4096;
  const Index num_blocks = (num_tets + kBlock - 1) / kBlock;
  std::vector<double> partial(num_blocks, 0.0);
  tbb::parallel_for(Index(0), num_blocks, [&](Index block) {
    double sum = 0.0;
    for (Index t = block * kBlock; t < std::min(num_tets, (block + 1) * kBlock); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          sum += (positions.row(tets(t, a)) - positions.row(tets(t, b))).norm();
    partial[block] = sum;
  });
  double sum = 0.0;
  for (const double block_sum : partial)
    sum += block_sum;
  return sum / (6.0 * static_cast<double>(num_tets));
}

double mean_triangle_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX3i> triangles) {
  double sum = 0.0;
  for (Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      sum += (positions.row(triangles(f, k)) - positions.row(triangles(f, (k + 1) % 3))).norm();
  return triangles.rows() > 0 ? sum / (3.0 * static_cast<double>(triangles.rows())) : 0.0;
}

}  // namespace strata
