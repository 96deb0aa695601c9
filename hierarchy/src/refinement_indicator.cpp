#include "strata/hierarchy/refinement_indicator.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace strata {

double RefinementIndicator::merge_indicator(const CutState&, const std::array<int, 8>&, int) const {
  return std::numeric_limits<double>::infinity();
}

double voigt_frobenius_norm(const Vector6d& voigt) {
  return std::sqrt(voigt.head<3>().squaredNorm() + 2.0 * voigt.tail<3>().squaredNorm());
}

VectorXd tet_stress_norms(const Eigen::Matrix<double, Eigen::Dynamic, 6>& cauchy_stress) {
  VectorXd norms(cauchy_stress.rows());
  for (Index t = 0; t < cauchy_stress.rows(); ++t)
    norms[t] = voigt_frobenius_norm(cauchy_stress.row(t).transpose());
  return norms;
}

VectorXd tet_rest_volumes(const TetMesh& mesh) {
  constexpr Index kChunk = 4096;  // tets per parallel task
  VectorXd volumes(mesh.tets.rows());
  tbb::parallel_for(Index(0), Index(mesh.tets.rows()), kChunk, [&](Index begin) {
    const Index end = std::min<Index>(begin + kChunk, mesh.tets.rows());
    for (Index t = begin; t < end; ++t)
      volumes[t] = tet_signed_volume(mesh.vertices.row(mesh.tets(t, 0)).transpose(),
                                     mesh.vertices.row(mesh.tets(t, 1)).transpose(),
                                     mesh.vertices.row(mesh.tets(t, 2)).transpose(),
                                     mesh.vertices.row(mesh.tets(t, 3)).transpose());
  });
  return volumes;
}

double volume_rms_stress(const CutState& state) {
  const VectorXd volumes = tet_rest_volumes(state.flat.mesh);
  const VectorXd norms = tet_stress_norms(state.fields.cauchy_stress);
  const double total = volumes.sum();
  if (!(total > 0.0)) return 0.0;
  return std::sqrt(volumes.dot(norms.cwiseAbs2()) / total);
}

}  // namespace strata
