#include "strata/core/mesh/point_location.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

/// Closest point to p on the triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
Vector3d closest_point_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                                   const Vector3d& c) {
  const Vector3d ab = b - a;
  const Vector3d ac = c - a;
  const Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

constexpr double kInsideEpsilon = 1e-12;

}  // namespace

Eigen::Vector4d tet_barycentric_coordinates(const Vector3d& p, const Vector3d& x0,
                                            const Vector3d& x1, const Vector3d& x2,
                                            const Vector3d& x3) {
  Matrix3d D;
  D.col(0) = x1 - x0;
  D.col(1) = x2 - x0;
  D.col(2) = x3 - x0;
  const Vector3d l = D.partialPivLu().solve(p - x0);
  return Eigen::Vector4d(1.0 - l.sum(), l(0), l(1), l(2));
}

double point_tet_distance(const Vector3d& p, const Vector3d& x0, const Vector3d& x1,
                          const Vector3d& x2, const Vector3d& x3) {
  const Eigen::Vector4d lambda = tet_barycentric_coordinates(p, x0, x1, x2, x3);
  if (lambda.minCoeff() >= 0.0) return 0.0;
  const Vector3d* x[4] = {&x0, &x1, &x2, &x3};
  double best = std::numeric_limits<double>::infinity();
  for (int skip = 0; skip < 4; ++skip) {
    const Vector3d& a = *x[(skip + 1) % 4];
    const Vector3d& b = *x[(skip + 2) % 4];
    const Vector3d& c = *x[(skip + 3) % 4];
    best = std::min(best, (closest_point_on_triangle(p, a, b, c) - p).norm());
  }
  return best;
}

TetLocator::TetLocator(ConstRef<MatrixX3d> vertices, ConstRef<MatrixX4i> tets)
    : m_vertices(vertices), m_tets(tets) {
  const Index num_tets = m_tets.rows();
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
  Vector3d hi = -lo;
  for (Index t = 0; t < num_tets; ++t) {
    for (int k = 0; k < 4; ++k) {
      lo = lo.cwiseMin(m_vertices.row(m_tets(t, k)).transpose());
      hi = hi.cwiseMax(m_vertices.row(m_tets(t, k)).transpose());
    }
  }
  if (num_tets == 0) lo = hi = Vector3d::Zero();
  const Vector3d extent = (hi - lo).cwiseMax(1e-300);
  // About one cell per tet, cells as close to cubes as the box allows.
  const double cell_volume = extent.prod() / std::max<Index>(num_tets, 1);
  const double edge = std::cbrt(std::max(cell_volume, 1e-300));
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil(extent(a) / std::max(edge, 1e-300));
    m_cells[a] = static_cast<int>(std::clamp(n, 1.0, 128.0));
  }
  m_origin = lo;
  m_cell_size = extent.cwiseQuotient(Vector3d(m_cells[0], m_cells[1], m_cells[2]));

  const auto cell_index = [this](int i, int j, int k) {
    return (static_cast<std::size_t>(k) * m_cells[1] + j) * m_cells[0] + i;
  };
  const std::size_t num_cells = static_cast<std::size_t>(m_cells[0]) * m_cells[1] * m_cells[2];
  std::vector<std::array<int, 3>> tet_lo(num_tets), tet_hi(num_tets);
  std::vector<int> count(num_cells + 1, 0);
  for (Index t = 0; t < num_tets; ++t) {
    Vector3d blo = m_vertices.row(m_tets(t, 0)).transpose();
    Vector3d bhi = blo;
    for (int k = 1; k < 4; ++k) {
      blo = blo.cwiseMin(m_vertices.row(m_tets(t, k)).transpose());
      bhi = bhi.cwiseMax(m_vertices.row(m_tets(t, k)).transpose());
    }
    tet_lo[t] = cell_of(blo);
    tet_hi[t] = cell_of(bhi);
    for (int k = tet_lo[t][2]; k <= tet_hi[t][2]; ++k)
      for (int j = tet_lo[t][1]; j <= tet_hi[t][1]; ++j)
        for (int i = tet_lo[t][0]; i <= tet_hi[t][0]; ++i)
          ++count[cell_index(i, j, k) + 1];
  }
  for (std::size_t c = 0; c < num_cells; ++c)
    count[c + 1] += count[c];
  m_cell_start = count;
  m_cell_tets.resize(m_cell_start.back());
  for (Index t = 0; t < num_tets; ++t) {
    for (int k = tet_lo[t][2]; k <= tet_hi[t][2]; ++k)
      for (int j = tet_lo[t][1]; j <= tet_hi[t][1]; ++j)
        for (int i = tet_lo[t][0]; i <= tet_hi[t][0]; ++i)
          m_cell_tets[count[cell_index(i, j, k)]++] = static_cast<int>(t);
  }
}

std::array<int, 3> TetLocator::cell_of(const Vector3d& p) const {
  std::array<int, 3> cell;
  for (int a = 0; a < 3; ++a) {
    const double s = std::floor((p(a) - m_origin(a)) / m_cell_size(a));
    cell[a] = static_cast<int>(std::clamp(s, 0.0, static_cast<double>(m_cells[a] - 1)));
  }
  return cell;
}

TetLocation TetLocator::evaluate(Index tet, const Vector3d& p) const {
  const Vector3d x0 = m_vertices.row(m_tets(tet, 0)).transpose();
  const Vector3d x1 = m_vertices.row(m_tets(tet, 1)).transpose();
  const Vector3d x2 = m_vertices.row(m_tets(tet, 2)).transpose();
  const Vector3d x3 = m_vertices.row(m_tets(tet, 3)).transpose();
  TetLocation location;
  location.tet = tet;
  location.barycentric = tet_barycentric_coordinates(p, x0, x1, x2, x3);
  location.distance = location.barycentric.minCoeff() >= -kInsideEpsilon
                          ? 0.0
                          : point_tet_distance(p, x0, x1, x2, x3);
  return location;
}

std::optional<TetLocation> TetLocator::locate(const Vector3d& p, double tolerance) const {
  if (m_tets.rows() == 0 || !p.allFinite()) return std::nullopt;
  const double reach = std::max(tolerance, 0.0);
  const Vector3d lo_point = p - Vector3d::Constant(reach);
  const Vector3d hi_point = p + Vector3d::Constant(reach);
  // Outside the grid by more than the tolerance: nothing can be near.
  const Vector3d grid_hi =
      m_origin + m_cell_size.cwiseProduct(Vector3d(m_cells[0], m_cells[1], m_cells[2]));
  if ((hi_point.array() < m_origin.array()).any() || (lo_point.array() > grid_hi.array()).any()) {
    return std::nullopt;
  }
  const std::array<int, 3> lo = cell_of(lo_point);
  const std::array<int, 3> hi = cell_of(hi_point);
  std::optional<TetLocation> best;
  for (int k = lo[2]; k <= hi[2]; ++k) {
    for (int j = lo[1]; j <= hi[1]; ++j) {
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const std::size_t c = (static_cast<std::size_t>(k) * m_cells[1] + j) * m_cells[0] + i;
        for (int n = m_cell_start[c]; n < m_cell_start[c + 1]; ++n) {
          const TetLocation candidate = evaluate(m_cell_tets[n], p);
          if (candidate.distance == 0.0) return candidate;
          if (candidate.distance <= reach && (!best || candidate.distance < best->distance)) {
            best = candidate;
          }
        }
      }
    }
  }
  return best;
}

std::vector<TetLocation> locate_points(const TetLocator& locator, ConstRef<MatrixX3d> points,
                                       double tolerance, const std::string& what) {
  std::vector<TetLocation> locations;
  locations.reserve(points.rows());
  for (Index i = 0; i < points.rows(); ++i) {
    const Vector3d p = points.row(i).transpose();
    std::optional<TetLocation> location = locator.locate(p, tolerance);
    if (!location) {
      std::ostringstream message;
      message << what << "." << i << ": point (" << p(0) << ", " << p(1) << ", " << p(2)
              << ") lies outside the mesh";
      throw InputError(message.str());
    }
    locations.push_back(*location);
  }
  return locations;
}

}  // namespace strata
