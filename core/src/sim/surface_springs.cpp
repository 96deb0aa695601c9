#include "strata/core/sim/surface_springs.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "strata/core/common/error.hpp"

namespace strata {

void validate_surface_springs(const SurfaceSpringSettings& s, const std::string& where) {
  if (!(s.youngs_modulus > 0.0) || !std::isfinite(s.youngs_modulus))
    throw InputError(where + ".youngs_modulus: must be positive and finite");
  if (!(s.yield_strain > 0.0)) throw InputError(where + ".yield_strain: must be positive");
  if (!(s.fraction > 0.0 && s.fraction <= 1.0))
    throw InputError(where + ".fraction: must be in (0, 1]");
}

SurfaceSprings::SurfaceSprings(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                               const SurfaceSpringSettings& settings)
    : m_settings(settings) {
  validate_surface_springs(settings, "material.surface_springs");
  std::vector<std::array<int, 2>> all;
  for (Index f = 0; f < boundary.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = boundary(f, k), b = boundary(f, (k + 1) % 3);
      all.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  std::mt19937 rng(settings.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const auto& edge : all)
    if (uniform(rng) < settings.fraction) m_set.edges.push_back(edge);
  if (m_set.edges.empty() && !all.empty()) m_set.edges.push_back(all.front());
  m_set.rest.resize(size());
  m_set.stiffness.resize(size());
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = m_set.edges[s];
    m_set.rest[s] = (rest_positions.row(b) - rest_positions.row(a)).norm();
    m_set.stiffness[s] = settings.youngs_modulus * m_set.rest[s];
  }
  m_initial_rest = m_set.rest;
}

Index SurfaceSprings::yield(ConstRef<VectorXd> x) {
  Index yielded = 0;
  const double limit = m_settings.yield_strain;
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = m_set.edges[s];
    const double length = (x.segment<3>(3 * b) - x.segment<3>(3 * a)).norm();
    const double strain = length / m_set.rest[s] - 1.0;
    if (strain > limit) {
      m_set.rest[s] = length / (1.0 + limit);
      ++yielded;
    } else if (strain < -limit) {
      m_set.rest[s] = length / (1.0 - limit);
      ++yielded;
    }
  }
  m_yield_events += yielded;
  return yielded;
}

double SurfaceSprings::largest_plastic_strain() const {
  double largest = 0.0;
  for (Index s = 0; s < size(); ++s)
    largest = std::max(largest, std::abs(std::log(m_set.rest[s] / m_initial_rest[s])));
  return largest;
}

}  // namespace strata
