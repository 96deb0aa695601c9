#include "strata/core/fem/tet_rest_data.hpp"

#include <Eigen/LU>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

TetRestData compute_tet_rest_data(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX4i> tets) {
  TetRestData rest;
  rest.Dm_inv.resize(tets.rows());
  rest.rest_volume.resize(tets.rows());
  for (Index t = 0; t < tets.rows(); ++t) {
    Vector3d x[4];
    for (int k = 0; k < 4; ++k) {
      const int v = tets(t, k);
      if (v < 0 || v >= rest_positions.rows())
        throw InputError("tet " + std::to_string(t) + ": vertex index " + std::to_string(v) +
                         " out of range");
      x[k] = rest_positions.row(v).transpose();
    }
    const double quality = tet_normalized_volume(x[0], x[1], x[2], x[3]);
    if (!(quality >= kDegenerateTetThreshold))
      throw InputError("tet " + std::to_string(t) +
                       (quality < 0.0 ? " is inverted at rest" : " is degenerate at rest"));
    Matrix3d Dm;
    Dm << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    rest.Dm_inv[t] = Dm.inverse();
    rest.rest_volume[t] = Dm.determinant() / 6.0;
  }
  return rest;
}

}  // namespace strata
