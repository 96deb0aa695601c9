#include "strata/meshing/surface_binding.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <sstream>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/meshing/triangle_bvh.hpp"

namespace strata {
namespace {

constexpr std::size_t kGrain = 1024;

Vector3d row3(ConstRef<MatrixX3d> m, Index r) {
  return m.row(r).transpose();
}

void check_points(ConstRef<MatrixX3d> points, const char* what) {
  for (Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) {
      std::ostringstream message;
      message << what << " vertex " << i << " has non-finite coordinates";
      throw InputError(message.str());
    }
  }
}

}  // namespace

TetBoundary tet_boundary(const TetMesh& mesh) {
  // Outward faces of a positively oriented tet, as local vertex triples.
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Face {
    std::array<int, 3> sorted;
    std::array<int, 3> oriented;
    int tet;
  };
  std::vector<Face> faces;
  faces.reserve(4 * mesh.tets.rows());
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const bool positive = tet_signed_volume(row3(mesh.vertices, mesh.tets(t, 0)),
                                            row3(mesh.vertices, mesh.tets(t, 1)),
                                            row3(mesh.vertices, mesh.tets(t, 2)),
                                            row3(mesh.vertices, mesh.tets(t, 3))) >= 0.0;
    for (const auto& local : kFaces) {
      Face face;
      face.oriented = {mesh.tets(t, local[0]), mesh.tets(t, local[1]), mesh.tets(t, local[2])};
      if (!positive) std::swap(face.oriented[1], face.oriented[2]);
      face.sorted = face.oriented;
      std::sort(face.sorted.begin(), face.sorted.end());
      face.tet = static_cast<int>(t);
      faces.push_back(face);
    }
  }
  std::sort(faces.begin(), faces.end(),
            [](const Face& a, const Face& b) { return a.sorted < b.sorted; });
  std::vector<const Face*> once;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].sorted == faces[i].sorted)
      ++j;
    if (j - i == 1) once.push_back(&faces[i]);
    i = j;
  }
  TetBoundary boundary;
  boundary.faces.resize(static_cast<Index>(once.size()), 3);
  boundary.tets.resize(static_cast<Index>(once.size()));
  for (std::size_t f = 0; f < once.size(); ++f) {
    boundary.faces.row(f) << once[f]->oriented[0], once[f]->oriented[1], once[f]->oriented[2];
    boundary.tets(f) = once[f]->tet;
  }
  return boundary;
}

SurfaceBinding bind_surface(const TetMesh& rest_mesh, ConstRef<MatrixX3d> surface_vertices) {
  if (rest_mesh.tets.rows() == 0) throw InputError("surface binding: the tet mesh is empty");
  check_points(surface_vertices, "surface binding: surface");
  const Index n = surface_vertices.rows();
  SurfaceBinding binding;
  binding.corners.resize(n, 4);
  binding.barycentric.resize(n, 4);
  binding.tets.resize(n);
  binding.distance.setZero(n);

  const TetLocator locator(rest_mesh.vertices, rest_mesh.tets);
  std::vector<char> outside(n, 0);
  std::atomic<Index> num_outside{0};
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, kGrain),
                    [&](const tbb::blocked_range<Index>& r) {
                      Index local_outside = 0;
                      for (Index i = r.begin(); i != r.end(); ++i) {
                        const std::optional<TetLocation> location =
                            locator.locate(row3(surface_vertices, i), 0.0);
                        if (location && location->distance == 0.0) {
                          binding.tets(i) = static_cast<int>(location->tet);
                          binding.barycentric.row(i) = location->barycentric.transpose();
                        } else {
                          outside[i] = 1;
                          ++local_outside;
                        }
                      }
                      num_outside += local_outside;
                    });
  binding.num_outside = num_outside.load();

  if (binding.num_outside > 0) {
    const TetBoundary boundary = tet_boundary(rest_mesh);
    const TriangleBvh bvh(rest_mesh.vertices, boundary.faces);
    tbb::parallel_for(
        tbb::blocked_range<Index>(0, n, kGrain), [&](const tbb::blocked_range<Index>& r) {
          for (Index i = r.begin(); i != r.end(); ++i) {
            if (!outside[i]) continue;
            const Vector3d p = row3(surface_vertices, i);
            const SurfaceClosestPoint closest = bvh.closest_point(p);
            const int t = boundary.tets(closest.triangle);
            binding.tets(i) = t;
            binding.distance(i) = closest.distance;
            binding.barycentric.row(i) =
                tet_barycentric_coordinates(p, row3(rest_mesh.vertices, rest_mesh.tets(t, 0)),
                                            row3(rest_mesh.vertices, rest_mesh.tets(t, 1)),
                                            row3(rest_mesh.vertices, rest_mesh.tets(t, 2)),
                                            row3(rest_mesh.vertices, rest_mesh.tets(t, 3)))
                    .transpose();
          }
        });
  }
  for (Index i = 0; i < n; ++i)
    binding.corners.row(i) = rest_mesh.tets.row(binding.tets(i));
  return binding;
}

MatrixX3d deformed_surface(const SurfaceBinding& binding, ConstRef<VectorXd> positions) {
  const Index n = binding.corners.rows();
  MatrixX3d deformed(n, 3);
  for (Index i = 0; i < n; ++i) {
    Vector3d x = Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      x += binding.barycentric(i, k) * positions.segment<3>(3 * binding.corners(i, k));
    deformed.row(i) = x.transpose();
  }
  return deformed;
}

DisplacementMap displacement_map(const TetMesh& rest_mesh, ConstRef<MatrixX3d> surface_vertices) {
  if (rest_mesh.tets.rows() == 0) throw InputError("displacement map: the tet mesh is empty");
  check_points(surface_vertices, "displacement map: surface");
  DisplacementMap map;
  map.boundary_faces = tet_boundary(rest_mesh).faces;
  const TriangleBvh bvh(rest_mesh.vertices, map.boundary_faces);
  const Index n = surface_vertices.rows();
  map.faces.resize(n);
  map.face_barycentric.resize(n, 3);
  map.offset.resize(n);
  tbb::parallel_for(
      tbb::blocked_range<Index>(0, n, kGrain), [&](const tbb::blocked_range<Index>& r) {
        for (Index i = r.begin(); i != r.end(); ++i) {
          const Vector3d p = row3(surface_vertices, i);
          const SurfaceClosestPoint closest = bvh.closest_point(p);
          const Vector3d x0 = row3(rest_mesh.vertices, map.boundary_faces(closest.triangle, 0));
          const Vector3d x1 = row3(rest_mesh.vertices, map.boundary_faces(closest.triangle, 1));
          const Vector3d x2 = row3(rest_mesh.vertices, map.boundary_faces(closest.triangle, 2));
          const Vector3d normal = (x1 - x0).cross(x2 - x0);
          map.faces(i) = static_cast<int>(closest.triangle);
          map.face_barycentric.row(i) = closest.barycentric.transpose();
          map.offset(i) =
              (p - closest.point).dot(normal) < 0.0 ? -closest.distance : closest.distance;
        }
      });
  return map;
}

MatrixX3d displaced_surface(const DisplacementMap& map, ConstRef<VectorXd> positions) {
  const Index n = map.faces.rows();
  MatrixX3d displaced(n, 3);
  for (Index i = 0; i < n; ++i) {
    const int f = map.faces(i);
    const Vector3d x0 = positions.segment<3>(3 * map.boundary_faces(f, 0));
    const Vector3d x1 = positions.segment<3>(3 * map.boundary_faces(f, 1));
    const Vector3d x2 = positions.segment<3>(3 * map.boundary_faces(f, 2));
    const Vector3d base = map.face_barycentric(i, 0) * x0 + map.face_barycentric(i, 1) * x1 +
                          map.face_barycentric(i, 2) * x2;
    displaced.row(i) = (base + map.offset(i) * (x1 - x0).cross(x2 - x0).normalized()).transpose();
  }
  return displaced;
}

}  // namespace strata
