#include "strata/meshing/triangle_frame_binding.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <string>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/meshing/surface_mesh.hpp"
#include "strata/meshing/triangle_bvh.hpp"

namespace strata {
namespace {

/// A triangle's orthonormal frame (t, n̂ × t, n̂) as columns and, given its corners' velocities,
/// the frame's time derivative. t follows edge `edge` (x_k → x_{k+1} for k = edge).
struct Frame {
  Matrix3d R;
  Matrix3d dR = Matrix3d::Zero();
};

/// d/dt of a / |a| for ȧ: (I − â âᵀ) ȧ / |a|; zero for a = 0.
Vector3d unit_rate(const Vector3d& a, const Vector3d& a_dot) {
  const double length = a.norm();
  if (!(length > 0.0)) return Vector3d::Zero();
  const Vector3d unit = a / length;
  return (a_dot - unit * unit.dot(a_dot)) / length;
}

Frame triangle_frame(const Vector3d* x, int edge, const Vector3d* v = nullptr) {
  const Vector3d e = x[(edge + 1) % 3] - x[edge];
  const Vector3d a = x[1] - x[0], b = x[2] - x[0];
  const Vector3d normal_vector = a.cross(b);
  Frame frame;
  const Vector3d t = e.normalized();  // Eigen leaves a zero vector unchanged
  const Vector3d n = normal_vector.normalized();
  frame.R.col(0) = t;
  frame.R.col(1) = n.cross(t);
  frame.R.col(2) = n;
  if (v != nullptr) {
    const Vector3d t_dot = unit_rate(e, v[(edge + 1) % 3] - v[edge]);
    const Vector3d n_dot = unit_rate(normal_vector, (v[1] - v[0]).cross(b) + a.cross(v[2] - v[0]));
    frame.dR.col(0) = t_dot;
    frame.dR.col(1) = n_dot.cross(t) + n.cross(t_dot);
    frame.dR.col(2) = n_dot;
  }
  return frame;
}

/// The edge of the rest triangle the frame's first axis follows: its longest.
int longest_edge(const Vector3d* x) {
  int best = 0;
  for (int k = 1; k < 3; ++k)
    if ((x[(k + 1) % 3] - x[k]).squaredNorm() > (x[(best + 1) % 3] - x[best]).squaredNorm())
      best = k;
  return best;
}

template <typename Points>
void corners(const Points& points, ConstRef<MatrixX3i> triangles, int f, Vector3d* x) {
  for (int k = 0; k < 3; ++k)
    x[k] = points(triangles(f, k));
}

}  // namespace

TriangleFrameBinding bind_to_triangles(ConstRef<MatrixX3d> coarse_vertices,
                                       ConstRef<MatrixX3i> coarse_triangles,
                                       ConstRef<MatrixX3d> fine_vertices) {
  const Index V = coarse_vertices.rows();
  for (Index f = 0; f < coarse_triangles.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = coarse_triangles(f, c);
      if (v < 0 || v >= V)
        throw InputError("coarse triangle " + std::to_string(f) + " names vertex " +
                         std::to_string(v) + " of " + std::to_string(V));
    }
  const SurfaceMesh coarse{coarse_vertices, coarse_triangles};
  std::vector<int> kept;
  for (Index f = 0; f < coarse_triangles.rows(); ++f)
    if (!is_degenerate_triangle(coarse, f)) kept.push_back(static_cast<int>(f));
  if (kept.empty()) throw InputError("the coarse surface has no triangle of positive area");
  MatrixX3i kept_triangles(static_cast<Index>(kept.size()), 3);
  for (std::size_t k = 0; k < kept.size(); ++k)
    kept_triangles.row(k) = coarse_triangles.row(kept[k]);
  for (Index i = 0; i < fine_vertices.rows(); ++i)
    if (!fine_vertices.row(i).allFinite())
      throw InputError("fine surface vertex " + std::to_string(i) + " is not finite");
  const TriangleBvh bvh(coarse_vertices, kept_triangles);

  const Index N = fine_vertices.rows();
  TriangleFrameBinding binding;
  binding.triangles.resize(N);
  binding.edges.resize(N);
  binding.barycentric.resize(N, 3);
  binding.offset.resize(N, 3);
  binding.distance.resize(N);
  const auto rest = [&](Index v) -> Vector3d { return coarse_vertices.row(v).transpose(); };
  tbb::parallel_for(tbb::blocked_range<Index>(0, N, 256), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) {
      const Vector3d X = fine_vertices.row(i).transpose();
      const SurfaceClosestPoint nearest = bvh.closest_point(X);
      const int f = kept[nearest.triangle];
      Vector3d x[3];
      corners(rest, coarse_triangles, f, x);
      const int edge = longest_edge(x);
      const Frame frame = triangle_frame(x, edge);
      const Vector3d p = nearest.barycentric[0] * x[0] + nearest.barycentric[1] * x[1] +
                         nearest.barycentric[2] * x[2];
      binding.triangles[i] = f;
      binding.edges[i] = edge;
      binding.barycentric.row(i) = nearest.barycentric.transpose();
      binding.offset.row(i) = (frame.R.transpose() * (X - p)).transpose();
      binding.distance[i] = nearest.distance;
    }
  });
  return binding;
}

namespace {

template <typename Each>
void for_each_bound(const TriangleFrameBinding& binding, Each&& each) {
  const Index N = binding.triangles.size();
  tbb::parallel_for(tbb::blocked_range<Index>(0, N, 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i)
      each(i);
  });
}

}  // namespace

MatrixX3d deformed_points(const TriangleFrameBinding& binding, ConstRef<MatrixX3i> coarse_triangles,
                          ConstRef<VectorXd> positions) {
  MatrixX3d points(binding.triangles.size(), 3);
  const auto at = [&](Index v) -> Vector3d { return positions.segment<3>(3 * v); };
  for_each_bound(binding, [&](Index i) {
    Vector3d x[3];
    corners(at, coarse_triangles, binding.triangles[i], x);
    const Frame frame = triangle_frame(x, binding.edges[i]);
    points.row(i) = (binding.barycentric(i, 0) * x[0] + binding.barycentric(i, 1) * x[1] +
                     binding.barycentric(i, 2) * x[2] + frame.R * binding.offset.row(i).transpose())
                        .transpose();
  });
  return points;
}

MatrixX3d deformed_velocities(const TriangleFrameBinding& binding,
                              ConstRef<MatrixX3i> coarse_triangles, ConstRef<VectorXd> positions,
                              ConstRef<VectorXd> velocities) {
  MatrixX3d result(binding.triangles.size(), 3);
  const auto at = [&](Index v) -> Vector3d { return positions.segment<3>(3 * v); };
  const auto rate = [&](Index v) -> Vector3d { return velocities.segment<3>(3 * v); };
  for_each_bound(binding, [&](Index i) {
    Vector3d x[3], v[3];
    corners(at, coarse_triangles, binding.triangles[i], x);
    corners(rate, coarse_triangles, binding.triangles[i], v);
    const Frame frame = triangle_frame(x, binding.edges[i], v);
    result.row(i) =
        (binding.barycentric(i, 0) * v[0] + binding.barycentric(i, 1) * v[1] +
         binding.barycentric(i, 2) * v[2] + frame.dR * binding.offset.row(i).transpose())
            .transpose();
  });
  return result;
}

}  // namespace strata
