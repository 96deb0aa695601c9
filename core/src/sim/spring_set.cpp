#include "strata/core/sim/spring_set.hpp"

#include <algorithm>

namespace strata {

double SpringSet::energy(ConstRef<VectorXd> x) const {
  double energy = 0.0;
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const double stretch = (x.segment<3>(3 * b) - x.segment<3>(3 * a)).norm() - rest[s];
    energy += 0.5 * stiffness[s] * stretch * stretch;
  }
  return energy;
}

void SpringSet::add_forces(ConstRef<VectorXd> x, VectorXd& f, double scale) const {
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const Vector3d d = x.segment<3>(3 * b) - x.segment<3>(3 * a);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Vector3d force = scale * stiffness[s] * (length - rest[s]) / length * d;
    f.segment<3>(3 * a) += force;
    f.segment<3>(3 * b) -= force;
  }
}

void SpringSet::add_hessian(ConstRef<VectorXd> x, SparseMatrixd& hessian, bool project_psd) const {
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const Vector3d d = x.segment<3>(3 * b) - x.segment<3>(3 * a);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Vector3d n = d / length;
    double transverse = 1.0 - rest[s] / length;
    if (project_psd) transverse = std::max(transverse, 0.0);
    const Matrix3d nn = n * n.transpose();
    const Matrix3d K = stiffness[s] * (nn + transverse * (Matrix3d::Identity() - nn));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        hessian.coeffRef(3 * a + r, 3 * a + c) += K(r, c);
        hessian.coeffRef(3 * b + r, 3 * b + c) += K(r, c);
        hessian.coeffRef(3 * a + r, 3 * b + c) -= K(r, c);
        hessian.coeffRef(3 * b + r, 3 * a + c) -= K(r, c);
      }
  }
}

void SpringSet::add_pattern(std::vector<Eigen::Triplet<double>>& triplets) const {
  for (const auto& [a, b] : edges)
    for (int i : {a, b})
      for (int j : {a, b})
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            triplets.emplace_back(3 * i + r, 3 * j + c, 0.0);
}

}  // namespace strata
