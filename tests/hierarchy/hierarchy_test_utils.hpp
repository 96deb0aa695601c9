#pragma once
// Shared helpers of the hierarchy tests: test tets, shape measures and similarity classes.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata::test {

/// A single-tet mesh with columns of `x` as vertices (in that order).
inline TetMesh single_tet_mesh(const Matrix3x4d& x) {
  TetMesh mesh;
  mesh.vertices = x.transpose();
  mesh.tets.resize(1, 4);
  mesh.tets << 0, 1, 2, 3;
  return mesh;
}

/// Regular tet with edge length 2√2 (alternate corners of a cube), positively oriented.
inline Matrix3x4d regular_tet() {
  Matrix3x4d x;
  x << 1, 1, -1, -1,  //
      1, -1, 1, -1,   //
      1, -1, -1, 1;
  if (tet_signed_volume(x.col(0), x.col(1), x.col(2), x.col(3)) < 0) x.col(2).swap(x.col(3));
  return x;
}

/// The first tet of a one-cell box mesh: a Kuhn (Freudenthal) tet, as core numbers it.
inline Matrix3x4d kuhn_tet() {
  const TetMesh box = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  Matrix3x4d x;
  for (int i = 0; i < 4; ++i)
    x.col(i) = box.vertices.row(box.tets(0, i)).transpose();
  return x;
}

/// An irregular, rather flat tet (minimum dihedral angle ≈ 24.5°), positively oriented.
inline Matrix3x4d skinny_tet() {
  Matrix3x4d x;
  x << 0.0, 1.0, 0.35, 0.4,  //
      0.0, 0.1, 0.3, 0.15,   //
      0.0, 0.0, 0.05, 1.7;
  return x;
}

/// Minimum dihedral angle [rad] over the six edges of the tet.
inline double min_dihedral_angle(const Matrix3x4d& x) {
  double smallest = M_PI;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      smallest = std::min(smallest, tet_dihedral_angle(x, a, b));
  return smallest;
}

/// A key equal for similar tets (mirror images included) and different otherwise: the
/// lexicographically smallest, over the 24 vertex orders, of the six squared edge lengths in a
/// fixed edge order, divided by the largest and rounded to 1e-9. Six edge lengths with their
/// incidences determine a tet up to isometry.
inline std::array<long long, 6> similarity_key(const Matrix3x4d& x) {
  std::array<int, 4> order{0, 1, 2, 3};
  std::array<long long, 6> best{};
  bool first = true;
  double longest = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      longest = std::max(longest, (x.col(a) - x.col(b)).squaredNorm());
  do {
    std::array<long long, 6> key{};
    int e = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        key[e++] = std::llround(1e9 * (x.col(order[a]) - x.col(order[b])).squaredNorm() / longest);
    if (first || key < best) best = key;
    first = false;
  } while (std::next_permutation(order.begin(), order.end()));
  return best;
}

}  // namespace strata::test
