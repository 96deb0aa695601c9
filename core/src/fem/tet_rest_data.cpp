#include "strata/core/fem/tet_rest_data.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {

TetRestData compute_tet_rest_data(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX4i> tets) {
  TetRestData rest;
  const Index num_tets = tets.rows();
  rest.Dm_inv.resize(num_tets);
  rest.rest_volume.resize(num_tets);
  // Per tet in parallel; the first bad tet (in tet order) is reported.
  enum Status : char { ok, out_of_range, inverted, degenerate };
  std::vector<char> status(num_tets, ok);
  tbb::parallel_for(tbb::blocked_range<Index>(0, num_tets, 1024),
                    [&](const tbb::blocked_range<Index>& range) {
                      for (Index t = range.begin(); t != range.end(); ++t) {
                        Vector3d x[4];
                        for (int k = 0; k < 4; ++k) {
                          const int v = tets(t, k);
                          if (v < 0 || v >= rest_positions.rows()) {
                            status[t] = out_of_range;
                            break;
                          }
                          x[k] = rest_positions.row(v).transpose();
                        }
                        if (status[t] != ok) continue;
                        const double quality = tet_normalized_volume(x[0], x[1], x[2], x[3]);
                        if (!(quality >= kDegenerateTetThreshold)) {
                          status[t] = quality < 0.0 ? inverted : degenerate;
                          continue;
                        }
                        Matrix3d Dm;
                        Dm << x[1] - x[0], x[2] - x[0], x[3] - x[0];
                        rest.Dm_inv[t] = Dm.inverse();
                        rest.rest_volume[t] = Dm.determinant() / 6.0;
                      }
                    });
  for (Index t = 0; t < num_tets; ++t) {
    if (status[t] == ok) continue;
    if (status[t] == out_of_range)
      for (int k = 0; k < 4; ++k) {
        const int v = tets(t, k);
        if (v < 0 || v >= rest_positions.rows())
          throw InputError("tet " + std::to_string(t) + ": vertex index " + std::to_string(v) +
                           " out of range");
      }
    throw InputError("tet " + std::to_string(t) +
                     (status[t] == inverted ? " is inverted at rest" : " is degenerate at rest"));
  }
  return rest;
}

}  // namespace strata
