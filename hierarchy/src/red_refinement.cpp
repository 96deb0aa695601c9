#include "strata/hierarchy/red_refinement.hpp"

#include <cmath>

#include "strata/core/common/error.hpp"

namespace strata {

Eigen::Matrix<double, 3, 10> refinement_points(const Matrix3x4d& x) {
  Eigen::Matrix<double, 3, 10> points;
  points.leftCols<4>() = x;
  for (int e = 0; e < 6; ++e)
    points.col(4 + e) = 0.5 * (x.col(kTetEdges[e][0]) + x.col(kTetEdges[e][1]));
  return points;
}

std::array<Matrix3x4d, 8> red_refine_tet(const Matrix3x4d& x) {
  const Eigen::Matrix<double, 3, 10> points = refinement_points(x);
  std::array<Matrix3x4d, 8> children;
  for (int k = 0; k < 8; ++k)
    for (int i = 0; i < 4; ++i)
      children[k].col(i) = points.col(kBeyChildren[k][i]);
  return children;
}

namespace {

// Column i of B_k holds the parent-barycentric coordinates of child k's vertex i, so λ = B_k μ.
std::array<Eigen::Matrix4d, 8> make_barycentric_maps() {
  Eigen::Matrix<double, 4, 10> points = Eigen::Matrix<double, 4, 10>::Zero();
  points.leftCols<4>().setIdentity();
  for (int e = 0; e < 6; ++e) {
    points(kTetEdges[e][0], 4 + e) = 0.5;
    points(kTetEdges[e][1], 4 + e) = 0.5;
  }
  std::array<Eigen::Matrix4d, 8> maps;
  for (int k = 0; k < 8; ++k) {
    Eigen::Matrix4d b;
    for (int i = 0; i < 4; ++i)
      b.col(i) = points.col(kBeyChildren[k][i]);
    const Eigen::Matrix4d inverse = b.inverse();
    maps[k] = inverse.array().round().matrix();
    STRATA_VERIFY((maps[k] - inverse).cwiseAbs().maxCoeff() < 1e-12,
                  "Bey child barycentric map is not integral");
  }
  return maps;
}

}  // namespace

const Eigen::Matrix4d& bey_child_barycentric_map(int child) {
  static const std::array<Eigen::Matrix4d, 8> maps = make_barycentric_maps();
  STRATA_VERIFY(child >= 0 && child < 8, "child slot must be in 0..7");
  return maps[child];
}

}  // namespace strata
