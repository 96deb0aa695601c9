#include "strata/meshing/triangle_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

constexpr int kLeafSize = 4;

double box_squared_distance(const Vector3d& p, const Vector3d& lo, const Vector3d& hi) {
  const Vector3d d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}

}  // namespace

Vector3d closest_point_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                                   const Vector3d& c, Vector3d& barycentric) {
  const Vector3d ab = b - a;
  const Vector3d ac = c - a;
  const Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    barycentric = Vector3d(1, 0, 0);
    return a;
  }
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    barycentric = Vector3d(0, 1, 0);
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    barycentric = Vector3d(1 - v, v, 0);
    return a + v * ab;
  }
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    barycentric = Vector3d(0, 0, 1);
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    barycentric = Vector3d(1 - w, 0, w);
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    barycentric = Vector3d(0, 1 - w, w);
    return b + w * (c - b);
  }
  const double sum = va + vb + vc;
  if (!(std::abs(sum) > 0.0)) {  // degenerate triangle: fall back to its first vertex
    barycentric = Vector3d(1, 0, 0);
    return a;
  }
  const double v = vb / sum;
  const double w = vc / sum;
  barycentric = Vector3d(1 - v - w, v, w);
  return a + v * ab + w * ac;
}

double triangle_solid_angle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                            const Vector3d& c) {
  const Vector3d x = a - p;
  const Vector3d y = b - p;
  const Vector3d z = c - p;
  const double lx = x.norm();
  const double ly = y.norm();
  const double lz = z.norm();
  const double numerator = x.dot(y.cross(z));
  const double denominator = lx * ly * lz + x.dot(y) * lz + y.dot(z) * lx + z.dot(x) * ly;
  return 2.0 * std::atan2(numerator, denominator);
}

TriangleBvh::TriangleBvh(ConstRef<MatrixX3d> vertices, ConstRef<MatrixX3i> triangles)
    : m_vertices(vertices), m_triangles(triangles) {
  const Index num_triangles = m_triangles.rows();
  if (num_triangles > 0 &&
      (m_triangles.minCoeff() < 0 || m_triangles.maxCoeff() >= m_vertices.rows())) {
    throw InputError("surface: a triangle refers to a vertex index outside 0.." +
                     std::to_string(m_vertices.rows() - 1));
  }
  if (num_triangles == 0) return;
  std::vector<Vector3d> centroids(num_triangles);
  m_order.resize(num_triangles);
  for (Index f = 0; f < num_triangles; ++f) {
    m_order[f] = static_cast<int>(f);
    centroids[f] = (m_vertices.row(m_triangles(f, 0)) + m_vertices.row(m_triangles(f, 1)) +
                    m_vertices.row(m_triangles(f, 2)))
                       .transpose() /
                   3.0;
  }
  m_nodes.reserve(2 * (num_triangles / kLeafSize + 1));
  m_nodes.resize(1);
  build(0, 0, static_cast<int>(num_triangles), centroids);
}

void TriangleBvh::build(int self, int begin, int end, const std::vector<Vector3d>& centroids) {
  Node node;
  node.lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
  node.hi = -node.lo;
  node.area_vector.setZero();
  Vector3d weighted_center = Vector3d::Zero();
  double total_area = 0.0;
  Vector3d centroid_lo = node.lo;
  Vector3d centroid_hi = node.hi;
  for (int n = begin; n < end; ++n) {
    const int f = m_order[n];
    const Vector3d x0 = m_vertices.row(m_triangles(f, 0)).transpose();
    const Vector3d x1 = m_vertices.row(m_triangles(f, 1)).transpose();
    const Vector3d x2 = m_vertices.row(m_triangles(f, 2)).transpose();
    node.lo = node.lo.cwiseMin(x0).cwiseMin(x1).cwiseMin(x2);
    node.hi = node.hi.cwiseMax(x0).cwiseMax(x1).cwiseMax(x2);
    const Vector3d area_vector = 0.5 * (x1 - x0).cross(x2 - x0);
    node.area_vector += area_vector;
    total_area += area_vector.norm();
    weighted_center += area_vector.norm() * centroids[f];
    centroid_lo = centroid_lo.cwiseMin(centroids[f]);
    centroid_hi = centroid_hi.cwiseMax(centroids[f]);
  }
  node.center = total_area > 0.0 ? Vector3d(weighted_center / total_area)
                                 : Vector3d(0.5 * (node.lo + node.hi));
  node.radius =
      (node.center - node.lo).cwiseAbs().cwiseMax((node.hi - node.center).cwiseAbs()).norm();
  if (end - begin <= kLeafSize) {
    node.first = begin;
    node.count = end - begin;
    m_nodes[self] = node;
    return;
  }
  int axis = 0;
  (centroid_hi - centroid_lo).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(m_order.begin() + begin, m_order.begin() + middle, m_order.begin() + end,
                   [&](int a, int b) { return centroids[a](axis) < centroids[b](axis); });
  const int left = static_cast<int>(m_nodes.size());
  node.first = left;
  node.count = 0;
  m_nodes[self] = node;
  m_nodes.resize(m_nodes.size() + 2);
  build(left, begin, middle, centroids);
  build(left + 1, middle, end, centroids);
}

SurfaceClosestPoint TriangleBvh::closest_point(const Vector3d& p) const {
  SurfaceClosestPoint best;
  if (m_nodes.empty()) return best;
  double best_squared = std::numeric_limits<double>::infinity();
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = m_nodes[stack[--top]];
    if (box_squared_distance(p, node.lo, node.hi) >= best_squared) continue;
    if (node.count > 0) {
      for (int n = node.first; n < node.first + node.count; ++n) {
        const int f = m_order[n];
        Vector3d barycentric;
        const Vector3d q =
            closest_point_on_triangle(p, m_vertices.row(m_triangles(f, 0)).transpose(),
                                      m_vertices.row(m_triangles(f, 1)).transpose(),
                                      m_vertices.row(m_triangles(f, 2)).transpose(), barycentric);
        const double squared = (q - p).squaredNorm();
        if (squared < best_squared) {
          best_squared = squared;
          best.triangle = f;
          best.point = q;
          best.barycentric = barycentric;
        }
      }
      continue;
    }
    // Visit the nearer child first: push it last.
    const int left = node.first;
    const double d_left = box_squared_distance(p, m_nodes[left].lo, m_nodes[left].hi);
    const double d_right = box_squared_distance(p, m_nodes[left + 1].lo, m_nodes[left + 1].hi);
    if (d_left <= d_right) {
      stack[top++] = left + 1;
      stack[top++] = left;
    } else {
      stack[top++] = left;
      stack[top++] = left + 1;
    }
  }
  best.distance = std::sqrt(best_squared);
  return best;
}

double TriangleBvh::winding_number(const Vector3d& p, double accuracy) const {
  if (m_nodes.empty()) return 0.0;
  double solid_angle = 0.0;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = m_nodes[stack[--top]];
    const Vector3d r = node.center - p;
    const double distance = r.norm();
    if (accuracy > 0.0 && distance > accuracy * node.radius) {
      solid_angle += node.area_vector.dot(r) / (distance * distance * distance);
      continue;
    }
    if (node.count > 0) {
      for (int n = node.first; n < node.first + node.count; ++n) {
        const int f = m_order[n];
        solid_angle += triangle_solid_angle(p, m_vertices.row(m_triangles(f, 0)).transpose(),
                                            m_vertices.row(m_triangles(f, 1)).transpose(),
                                            m_vertices.row(m_triangles(f, 2)).transpose());
      }
      continue;
    }
    stack[top++] = node.first;
    stack[top++] = node.first + 1;
  }
  return solid_angle / (4.0 * std::numbers::pi);
}

}  // namespace strata
