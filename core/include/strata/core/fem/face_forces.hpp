#pragma once
/// \file face_forces.hpp
/// The lecture's force recipe: per face of the deformed tet the traction σ·n·A (Cauchy stress σ,
/// outward unit normal n, area A); the element pulls on its vertices with the opposite of the
/// traction its faces receive, a third of each face's share to each of the face's vertices. For
/// σ = P Fᵀ/J this equals the energy-gradient force −∂W/∂x exactly (tested).
#include "strata/core/common/types.hpp"

namespace strata {

/// Forces (x0..x3 as columns of the 3 × 4 result) that a tet with Cauchy stress `sigma` exerts on
/// its vertices at deformed positions `x`, by the face-traction recipe.
Matrix3x4d tet_face_forces(const Matrix3x4d& x, const Matrix3d& sigma);

}  // namespace strata
