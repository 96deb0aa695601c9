#include "strata/core/sim/stable_time_step.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "strata/core/fem/deformation_gradient.hpp"

namespace strata {

double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material) {
  const LameParameters lame = material.lame();
  double max_gradient_eigenvalue = 0.0;
  for (Index t = 0; t < tets.rows(); ++t) {
    Matrix3x4d x;
    for (int k = 0; k < 4; ++k)
      x.col(k) = positions.row(tets(t, k)).transpose();
    const Matrix3d Dm = edge_matrix(x);
    if (!(std::abs(Dm.determinant()) > 0.0)) continue;  // degenerate tets are rejected earlier
    const Eigen::Matrix<double, 4, 3> G = shape_function_gradients(Dm.inverse());
    const Matrix3d GGt = G.transpose() * G;
    max_gradient_eigenvalue =
        std::max(max_gradient_eigenvalue,
                 Eigen::SelfAdjointEigenSolver<Matrix3d>(GGt, Eigen::EigenvaluesOnly)
                     .eigenvalues()
                     .maxCoeff());
  }
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
  double sum = 0.0;
  for (Index t = 0; t < tets.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        sum += (positions.row(tets(t, a)) - positions.row(tets(t, b))).norm();
  return tets.rows() > 0 ? sum / (6.0 * static_cast<double>(tets.rows())) : 0.0;
}

double mean_triangle_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX3i> triangles) {
  double sum = 0.0;
  for (Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      sum += (positions.row(triangles(f, k)) - positions.row(triangles(f, (k + 1) % 3))).norm();
  return triangles.rows() > 0 ? sum / (3.0 * static_cast<double>(triangles.rows())) : 0.0;
}

}  // namespace strata
