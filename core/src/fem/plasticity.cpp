#include "strata/core/fem/plasticity.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/SVD>
#include <atomic>
#include <cmath>

#include "strata/core/common/error.hpp"
#include "strata/core/fem/elastic_model.hpp"

namespace strata {

void validate_plasticity(const Plasticity& p, const std::string& where) {
  if (!(p.yield_stress > 0.0) || !std::isfinite(p.yield_stress))
    throw InputError(where + ".yield_stress: must be positive and finite");
  if (!(p.hardening >= 0.0) || !std::isfinite(p.hardening))
    throw InputError(where + ".hardening: must be >= 0 and finite");
  if (!(p.max_plastic_strain > 0.0))
    throw InputError(where + ".max_plastic_strain: must be positive");
}

PlasticState PlasticState::identity(Index num_tets) {
  PlasticState state;
  state.plastic_inverse.assign(num_tets, Matrix3d::Identity());
  state.equivalent_strain = VectorXd::Zero(num_tets);
  return state;
}

namespace {

constexpr double kMinSingularValue = 1e-12;

}  // namespace

double hencky_equivalent_stress(const Matrix3d& Fe, const LameParameters& lame) {
  const Eigen::JacobiSVD<Matrix3d> svd(Fe);
  const Vector3d sigma = svd.singularValues();
  if (sigma.minCoeff() <= kMinSingularValue || Fe.determinant() <= 0.0) return 0.0;
  const Vector3d strain = sigma.array().log();
  const Vector3d deviator = strain.array() - strain.mean();
  return std::sqrt(6.0) * lame.mu * deviator.norm();
}

ElementReturn return_map(const Matrix3d& F, const Matrix3d& plastic_inverse,
                         double equivalent_strain, const LameParameters& lame,
                         const Plasticity& plasticity) {
  ElementReturn result{plastic_inverse, equivalent_strain, false};
  const Matrix3d Fe = F * plastic_inverse;
  if (Fe.determinant() <= 0.0) return result;
  const Eigen::JacobiSVD<Matrix3d> svd(Fe, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vector3d sigma = svd.singularValues();
  if (sigma.minCoeff() <= kMinSingularValue) return result;
  const Vector3d strain = sigma.array().log();
  const Vector3d deviator = strain.array() - strain.mean();
  const double deviator_norm = deviator.norm();
  const double q = std::sqrt(6.0) * lame.mu * deviator_norm;
  const double yield = plasticity.yield_stress + plasticity.hardening * equivalent_strain;
  const double f = q - yield;
  if (!(f > 0.0) || deviator_norm == 0.0) return result;
  double increment = f / (3.0 * lame.mu + plasticity.hardening);
  increment = std::min(increment, plasticity.max_plastic_strain - equivalent_strain);
  if (!(increment > 0.0)) return result;
  // Δε = −Δε̄ √(3/2) n along the unit deviator n; traceless, so det e^{Δε} = 1.
  const Vector3d delta = -increment * std::sqrt(1.5) * deviator / deviator_norm;
  const Matrix3d& V = svd.matrixV();
  result.plastic_inverse =
      plastic_inverse * (V * delta.array().exp().matrix().asDiagonal() * V.transpose());
  result.equivalent_strain = equivalent_strain + increment;
  result.yielded = true;
  return result;
}

PlasticState return_map(const ElasticModel& model, ConstRef<VectorXd> x, const PlasticState& start,
                        const Plasticity& plasticity, Index* yielded) {
  const Index num_tets = model.num_tets();
  STRATA_VERIFY(
      start.num_tets() == num_tets && static_cast<Index>(start.plastic_inverse.size()) == num_tets,
      "return_map: plastic state does not match the mesh");
  STRATA_VERIFY(x.size() == model.num_dofs(), "return_map: position vector size");
  const LameParameters lame = model.material().lame();
  const MatrixX4i& tets = model.tets();
  const std::vector<Matrix3d>& Dm_inv = model.rest_data().Dm_inv;
  PlasticState next = start;
  std::atomic<Index> count{0};
  tbb::parallel_for(Index(0), num_tets, [&](Index t) {
    const Vector3d x0 = x.segment<3>(3 * tets(t, 0));
    Matrix3d Ds;
    for (int k = 0; k < 3; ++k)
      Ds.col(k) = x.segment<3>(3 * tets(t, k + 1)) - x0;
    const ElementReturn r = return_map(Ds * Dm_inv[t], start.plastic_inverse[t],
                                       start.equivalent_strain[t], lame, plasticity);
    if (!r.yielded) return;
    next.plastic_inverse[t] = r.plastic_inverse;
    next.equivalent_strain[t] = r.equivalent_strain;
    count.fetch_add(1, std::memory_order_relaxed);
  });
  if (yielded != nullptr) *yielded = count.load();
  return next;
}

}  // namespace strata
