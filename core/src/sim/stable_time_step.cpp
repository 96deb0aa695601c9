#include "strata/core/sim/stable_time_step.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

namespace strata {

double min_tet_altitude(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets) {
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  double smallest = std::numeric_limits<double>::infinity();
  for (Index t = 0; t < tets.rows(); ++t) {
    Vector3d x[4];
    for (int k = 0; k < 4; ++k)
      x[k] = positions.row(tets(t, k)).transpose();
    const double volume = std::abs((x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0]))) / 6.0;
    double max_area = 0.0;
    for (const auto& f : kFaces)
      max_area = std::max(max_area, 0.5 * (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]).norm());
    if (max_area > 0.0) smallest = std::min(smallest, 3.0 * volume / max_area);
  }
  return smallest;
}

double stable_time_step_estimate(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 double p_wave_speed) {
  return min_tet_altitude(positions, tets) / p_wave_speed;
}

double mean_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets) {
  double sum = 0.0;
  for (Index t = 0; t < tets.rows(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        sum += (positions.row(tets(t, a)) - positions.row(tets(t, b))).norm();
  return tets.rows() > 0 ? sum / (6.0 * static_cast<double>(tets.rows())) : 0.0;
}

}  // namespace strata
