#include "strata/core/fem/face_forces.hpp"

namespace strata {

Matrix3x4d tet_face_forces(const Matrix3x4d& x, const Matrix3d& sigma) {
  // Outward faces of a positively oriented tet; (b − a) × (c − a) = 2 · area · outward normal.
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  Matrix3x4d forces = Matrix3x4d::Zero();
  for (const auto& face : kFaces) {
    const Vector3d area_normal =
        0.5 * (x.col(face[1]) - x.col(face[0])).cross(x.col(face[2]) - x.col(face[0]));
    const Vector3d traction_force = sigma * area_normal;  // σ · n · A
    for (int k = 0; k < 3; ++k)
      forces.col(face[k]) -= traction_force / 3.0;
  }
  return forces;
}

}  // namespace strata
