#pragma once
/// \file green_strain.hpp
/// Green–Lagrange strain E = ½(FᵀF − I) = ½(∇u + ∇uᵀ + ∇uᵀ∇u), invariant to rigid motion.
#include "strata/core/common/types.hpp"

namespace strata {

/// Green strain of deformation gradient F.
inline Matrix3d green_strain(const Matrix3d& F) {
  return 0.5 * (F.transpose() * F - Matrix3d::Identity());
}

}  // namespace strata
