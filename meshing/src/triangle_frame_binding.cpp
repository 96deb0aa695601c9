#include "strata/meshing/triangle_frame_binding.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <string>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/meshing/triangle_bvh.hpp"

namespace strata {
namespace {

/// The frame (x1 − x0, x2 − x0, n̂) of a triangle as matrix columns.
Matrix3d triangle_frame(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2) {
  Matrix3d frame;
  frame.col(0) = x1 - x0;
  frame.col(1) = x2 - x0;
  frame.col(2) = frame.col(0).cross(frame.col(1)).normalized();
  return frame;
}

bool degenerate(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2) {
  const double longest =
      std::max({(x1 - x0).squaredNorm(), (x2 - x1).squaredNorm(), (x0 - x2).squaredNorm()});
  return !((x1 - x0).cross(x2 - x0).norm() > 1e-14 * longest);
}

}  // namespace

TriangleFrameBinding bind_to_triangles(ConstRef<MatrixX3d> coarse_vertices,
                                       ConstRef<MatrixX3i> coarse_triangles,
                                       ConstRef<MatrixX3d> fine_vertices) {
  const Index V = coarse_vertices.rows();
  std::vector<int> kept;
  for (Index f = 0; f < coarse_triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = coarse_triangles(f, c);
      if (v < 0 || v >= V)
        throw InputError("coarse triangle " + std::to_string(f) + " names vertex " +
                         std::to_string(v) + " of " + std::to_string(V));
    }
    if (!degenerate(coarse_vertices.row(coarse_triangles(f, 0)).transpose(),
                    coarse_vertices.row(coarse_triangles(f, 1)).transpose(),
                    coarse_vertices.row(coarse_triangles(f, 2)).transpose()))
      kept.push_back(static_cast<int>(f));
  }
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
  binding.coefficients.resize(N, 3);
  binding.distance.resize(N);
  tbb::parallel_for(tbb::blocked_range<Index>(0, N, 256), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) {
      const Vector3d X = fine_vertices.row(i).transpose();
      const SurfaceClosestPoint nearest = bvh.closest_point(X);
      const int f = kept[nearest.triangle];
      const Vector3d x0 = coarse_vertices.row(coarse_triangles(f, 0)).transpose();
      const Matrix3d frame =
          triangle_frame(x0, coarse_vertices.row(coarse_triangles(f, 1)).transpose(),
                         coarse_vertices.row(coarse_triangles(f, 2)).transpose());
      binding.triangles[i] = f;
      binding.coefficients.row(i) = frame.partialPivLu().solve(X - x0).transpose();
      binding.distance[i] = nearest.distance;
    }
  });
  return binding;
}

MatrixX3d deformed_points(const TriangleFrameBinding& binding, ConstRef<MatrixX3i> coarse_triangles,
                          ConstRef<VectorXd> positions) {
  const Index N = binding.triangles.size();
  MatrixX3d points(N, 3);
  tbb::parallel_for(tbb::blocked_range<Index>(0, N, 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) {
      const int f = binding.triangles[i];
      const Vector3d x0 = positions.segment<3>(3 * coarse_triangles(f, 0));
      const Matrix3d frame = triangle_frame(x0, positions.segment<3>(3 * coarse_triangles(f, 1)),
                                            positions.segment<3>(3 * coarse_triangles(f, 2)));
      points.row(i) = (x0 + frame * binding.coefficients.row(i).transpose()).transpose();
    }
  });
  return points;
}

}  // namespace strata
