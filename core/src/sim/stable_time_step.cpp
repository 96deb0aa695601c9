#include "strata/core/sim/stable_time_step.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "strata/core/fem/deformation_gradient.hpp"

namespace strata {

namespace {

/// The closed-form element bound on ω_t² without the factor 4 (3λ + 2μ) / ρ: λ_max(G Gᵀ), 0 for
/// a degenerate tet (rejected earlier).
double gradient_eigenvalue(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets, Index t) {
  Matrix3x4d x;
  for (int k = 0; k < 4; ++k)
    x.col(k) = positions.row(tets(t, k)).transpose();
  const Matrix3d Dm = edge_matrix(x);
  if (!(std::abs(Dm.determinant()) > 0.0)) return 0.0;
  const Eigen::Matrix<double, 4, 3> G = shape_function_gradients(Dm.inverse());
  const Matrix3d GGt = G.transpose() * G;
  return Eigen::SelfAdjointEigenSolver<Matrix3d>(GGt, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

/// ω_g² of a group: the largest eigenvalue of M_g^-½ K_g M_g^-½, K_g the group's linear
/// isotropic stiffness at rest, block (a, b) of a tet V [μ (g_a·g_b) I + μ g_b g_aᵀ + λ g_a g_bᵀ]
/// (g_a = ∇N_a), M_g its lumped masses.
double group_frequency_squared(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                               std::span<const int> members, const LameParameters& lame,
                               double density) {
  std::vector<int> vertices;  // the group's vertices, in the order met
  vertices.reserve(4 * members.size());
  const auto local = [&vertices](int v) {
    const auto found = std::find(vertices.begin(), vertices.end(), v);
    if (found != vertices.end()) return static_cast<Index>(found - vertices.begin());
    vertices.push_back(v);
    return static_cast<Index>(vertices.size() - 1);
  };
  std::vector<std::array<Index, 4>> corners(members.size());
  for (std::size_t i = 0; i < members.size(); ++i)
    for (int k = 0; k < 4; ++k)
      corners[i][k] = local(tets(members[i], k));
  const Index n = static_cast<Index>(vertices.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  VectorXd mass = VectorXd::Zero(n);
  for (std::size_t i = 0; i < members.size(); ++i) {
    Matrix3x4d x;
    for (int k = 0; k < 4; ++k)
      x.col(k) = positions.row(tets(members[i], k)).transpose();
    const Matrix3d Dm = edge_matrix(x);
    const double volume = std::abs(Dm.determinant()) / 6.0;
    if (!(volume > 0.0)) continue;  // degenerate tets are rejected earlier
    const Eigen::Matrix<double, 4, 3> G = shape_function_gradients(Dm.inverse());
    for (int a = 0; a < 4; ++a) {
      mass[corners[i][a]] += density * volume / 4.0;
      for (int b = 0; b < 4; ++b) {
        const Vector3d ga = G.row(a).transpose(), gb = G.row(b).transpose();
        K.block<3, 3>(3 * corners[i][a], 3 * corners[i][b]) +=
            volume * (lame.mu * ga.dot(gb) * Matrix3d::Identity() + lame.mu * gb * ga.transpose() +
                      lame.lambda * ga * gb.transpose());
      }
    }
  }
  VectorXd inverse_sqrt_mass(3 * n);
  for (Index i = 0; i < 3 * n; ++i)
    inverse_sqrt_mass[i] = mass[i / 3] > 0.0 ? 1.0 / std::sqrt(mass[i / 3]) : 0.0;
  const Eigen::MatrixXd scaled =
      inverse_sqrt_mass.asDiagonal() * K * inverse_sqrt_mass.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

}  // namespace

double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material) {
  return max_angular_frequency_bound(positions, tets, material, {});
}

double max_angular_frequency_bound(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                   const Material& material, std::span<const int> groups) {
  const LameParameters lame = material.lame();
  const Index num_tets = tets.rows();
  if (!groups.empty() && static_cast<Index>(groups.size()) != num_tets)
    throw std::invalid_argument("max_angular_frequency_bound: " + std::to_string(groups.size()) +
                                " group ids for " + std::to_string(num_tets) + " tets");
  // Tets on their own: the largest λ_max(G Gᵀ) (exact in any order, so in parallel).
  const double max_gradient_eigenvalue = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, num_tets, 1024), 0.0,
      [&](const tbb::blocked_range<Index>& range, double largest) {
        for (Index t = range.begin(); t != range.end(); ++t)
          if (groups.empty() || groups[t] < 0)
            largest = std::max(largest, gradient_eigenvalue(positions, tets, t));
        return largest;
      },
      [](double a, double b) { return std::max(a, b); });
  double largest =
      4.0 * (3.0 * lame.lambda + 2.0 * lame.mu) * max_gradient_eigenvalue / material.density;
  if (groups.empty()) return std::sqrt(largest);
  // The groups: their tets listed by id, each group's eigenproblem in parallel.
  std::vector<std::pair<int, int>> members;  // (group, tet)
  for (Index t = 0; t < num_tets; ++t)
    if (groups[t] >= 0) members.emplace_back(groups[t], static_cast<int>(t));
  std::sort(members.begin(), members.end());
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < members.size(); ++i)
    if (i == 0 || members[i].first != members[i - 1].first) starts.push_back(i);
  starts.push_back(members.size());
  std::vector<int> tet_of(members.size());
  for (std::size_t i = 0; i < members.size(); ++i)
    tet_of[i] = members[i].second;
  for (std::size_t g = 0; g + 1 < starts.size(); ++g)
    if (starts[g + 1] - starts[g] > static_cast<std::size_t>(kMaxStabilityGroupTets))
      throw std::invalid_argument("max_angular_frequency_bound: group " +
                                  std::to_string(members[starts[g]].first) + " has " +
                                  std::to_string(starts[g + 1] - starts[g]) + " tets (at most " +
                                  std::to_string(kMaxStabilityGroupTets) + ")");
  const double largest_group = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, starts.size() - 1, 16), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double value) {
        for (std::size_t g = range.begin(); g != range.end(); ++g)
          value = std::max(
              value, group_frequency_squared(
                         positions, tets,
                         std::span<const int>(tet_of.data() + starts[g], starts[g + 1] - starts[g]),
                         lame, material.density));
        return value;
      },
      [](double a, double b) { return std::max(a, b); });
  largest = std::max(largest, largest_group);
  return std::sqrt(largest);
}

double explicit_stability_interval(Integrator integrator) {
  return integrator == Integrator::rk4 ? 2.0 * std::sqrt(2.0) : 2.0;
}

double stable_time_step_estimate(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets,
                                 const Material& material, Integrator integrator,
                                 std::span<const int> groups) {
  return explicit_stability_interval(integrator) /
         max_angular_frequency_bound(positions, tets, material, groups);
}

double mean_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX4i> tets) {
  // Partial sums over fixed blocks of tets, added in block order: the same value for every
  // number of threads.
  const Index num_tets = tets.rows();
  if (num_tets == 0) return 0.0;
  constexpr Index kBlock = 4096;
  const Index num_blocks = (num_tets + kBlock - 1) / kBlock;
  std::vector<double> partial(num_blocks, 0.0);
  tbb::parallel_for(Index(0), num_blocks, [&](Index block) {
    double sum = 0.0;
    for (Index t = block * kBlock; t < std::min(num_tets, (block + 1) * kBlock); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          sum += (positions.row(tets(t, a)) - positions.row(tets(t, b))).norm();
    partial[block] = sum;
  });
  double sum = 0.0;
  for (const double block_sum : partial)
    sum += block_sum;
  return sum / (6.0 * static_cast<double>(num_tets));
}

double mean_triangle_edge_length(ConstRef<MatrixX3d> positions, ConstRef<MatrixX3i> triangles) {
  double sum = 0.0;
  for (Index f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      sum += (positions.row(triangles(f, k)) - positions.row(triangles(f, (k + 1) % 3))).norm();
  return triangles.rows() > 0 ? sum / (3.0 * static_cast<double>(triangles.rows())) : 0.0;
}

}  // namespace strata
