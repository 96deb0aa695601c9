#pragma once
/// \file types.hpp
/// Eigen aliases used across strata.
///
/// DOF layout (the only one in strata): a state vector of a mesh with #V vertices has 3·#V entries,
/// vertex-major: (x0, y0, z0, x1, y1, z1, ...). `flatten` / `unflatten` convert between that and
/// the #V × 3 matrices that meshes and file readers use.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SparseCore>

namespace strata {

using Index = Eigen::Index;
using Vector3d = Eigen::Vector3d;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Vector9d = Eigen::Matrix<double, 9, 1>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix3d = Eigen::Matrix3d;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Matrix3x4d = Eigen::Matrix<double, 3, 4>;
using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3>;
using MatrixX4i = Eigen::Matrix<int, Eigen::Dynamic, 4>;
using MatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3>;
using VectorXd = Eigen::VectorXd;
using VectorXi = Eigen::VectorXi;
using SparseMatrixd = Eigen::SparseMatrix<double>;

/// Read-only view of any Eigen object of type T (no copy when layouts match).
template <typename T>
using ConstRef = const Eigen::Ref<const T>&;

/// #V × 3 positions → 3·#V vertex-major vector.
inline VectorXd flatten(ConstRef<MatrixX3d> positions) {
  VectorXd flat(3 * positions.rows());
  for (Index v = 0; v < positions.rows(); ++v)
    flat.segment<3>(3 * v) = positions.row(v).transpose();
  return flat;
}

/// 3·#V vertex-major vector → #V × 3 positions.
inline MatrixX3d unflatten(ConstRef<VectorXd> flat) {
  MatrixX3d positions(flat.size() / 3, 3);
  for (Index v = 0; v < positions.rows(); ++v)
    positions.row(v) = flat.segment<3>(3 * v).transpose();
  return positions;
}

}  // namespace strata
