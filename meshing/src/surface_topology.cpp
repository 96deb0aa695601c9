#include "strata/meshing/surface_topology.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {

std::string SurfaceTopology::summary() const {
  return std::string(watertight() ? "watertight" : "not watertight") + ": " +
         std::to_string(boundary_edges) + " boundary edges, " + std::to_string(non_manifold_edges) +
         " non-manifold edges, " + std::to_string(misoriented_edges) + " misoriented edges, " +
         std::to_string(degenerate_triangles) + " degenerate triangles";
}

SurfaceTopology surface_topology(const SurfaceMesh& surface) {
  const Index num_vertices = surface.vertices.rows();
  const MatrixX3i& triangles = surface.triangles;
  if (triangles.rows() > 0 && (triangles.minCoeff() < 0 || triangles.maxCoeff() >= num_vertices)) {
    throw InputError("surface: a triangle refers to a vertex index outside 0.." +
                     std::to_string(num_vertices - 1));
  }
  SurfaceTopology topology;
  // One record per directed edge: (min, max, +1 if min → max else −1), sorted by edge.
  struct HalfEdge {
    std::int64_t key;
    int direction;
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * triangles.rows());
  for (Index f = 0; f < triangles.rows(); ++f) {
    const int a = triangles(f, 0), b = triangles(f, 1), c = triangles(f, 2);
    const Vector3d x0 = surface.vertices.row(a).transpose();
    const Vector3d area =
        (surface.vertices.row(b).transpose() - x0).cross(surface.vertices.row(c).transpose() - x0);
    if (a == b || b == c || a == c || !(area.norm() > 0.0)) {
      ++topology.degenerate_triangles;
      if (a == b || b == c || a == c) continue;
    }
    const int corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      const std::int64_t from = corners[k];
      const std::int64_t to = corners[(k + 1) % 3];
      half_edges.push_back(
          {std::min(from, to) * num_vertices + std::max(from, to), from < to ? 1 : -1});
    }
  }
  std::sort(half_edges.begin(), half_edges.end(),
            [](const HalfEdge& x, const HalfEdge& y) { return x.key < y.key; });
  for (std::size_t i = 0; i < half_edges.size();) {
    std::size_t j = i;
    int direction_sum = 0;
    while (j < half_edges.size() && half_edges[j].key == half_edges[i].key) {
      direction_sum += half_edges[j].direction;
      ++j;
    }
    const std::size_t uses = j - i;
    ++topology.edges;
    if (uses == 1) {
      ++topology.boundary_edges;
    } else if (uses > 2) {
      ++topology.non_manifold_edges;
    } else if (direction_sum != 0) {
      ++topology.misoriented_edges;
    }
    i = j;
  }
  return topology;
}

}  // namespace strata
