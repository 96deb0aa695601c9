// CGAL unit (built in strata_meshing_cgal, see CMakeLists.txt).
// The skeletonization's CGAL containers draw from a MonotoneArena (see monotone_arena.hpp), so
// the skeleton does not depend on the state of the heap; defined before any CGAL header.
#include "monotone_arena.hpp"
#define CGAL_ALLOCATOR(T) strata::detail::MonotoneAllocator<T>

#include "strata/meshing/curve_skeleton.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/extract_mean_curvature_flow_skeleton.h>

#include <chrono>
#include <limits>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Skeletonization = CGAL::Mean_curvature_flow_skeletonization<Mesh>;
using Skeleton = Skeletonization::Skeleton;

// The armadillo's 26,002 vertices used 33 MB (1.3 KB a vertex); the reservation is 25× that.
constexpr std::size_t kArenaBase = std::size_t(1) << 28;       // 256 MiB
constexpr std::size_t kArenaPerVertex = std::size_t(1) << 15;  // 32 KiB

}  // namespace

CurveSkeleton curve_skeleton(const SurfaceMesh& surface, const std::string& where) {
  const auto start = std::chrono::steady_clock::now();
  if (surface.vertices.rows() < 4 || surface.triangles.rows() < 4)
    throw InputError(where + ": a skeleton needs a closed surface (at least 4 vertices)");
  Mesh mesh;
  std::vector<Mesh::Vertex_index> handles;
  handles.reserve(surface.vertices.rows());
  for (Index v = 0; v < surface.vertices.rows(); ++v)
    handles.push_back(mesh.add_vertex(
        Point(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2))));
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    const auto face =
        mesh.add_face(handles[surface.triangles(f, 0)], handles[surface.triangles(f, 1)],
                      handles[surface.triangles(f, 2)]);
    if (face == Mesh::null_face())
      throw InputError(where + ": triangle " + std::to_string(f) +
                       " breaks the 2-manifold (a skeleton needs a closed manifold surface)");
  }
  if (!CGAL::is_closed(mesh))
    throw InputError(where + ": the surface has holes (a skeleton needs a closed surface)");
  if (!CGAL::is_triangle_mesh(mesh)) throw InputError(where + ": not a triangle mesh");
  Skeleton skeleton;
  {
    // Address space for the skeletonization's copy of the surface and its Delaunay poles; pages
    // are committed only as they are used.
    detail::MonotoneArena arena(kArenaBase + kArenaPerVertex * surface.vertices.rows());
    try {
      CGAL::extract_mean_curvature_flow_skeleton(mesh, skeleton);
    } catch (const std::bad_alloc&) {
      const bool arena_full = arena.reserved() && arena.used() + (1u << 20) > arena.capacity();
      throw InputError(
          where + ": skeletonization ran out of memory" +
          (arena_full ? " (its arena of " + std::to_string(arena.capacity() >> 20) + " MiB is full)"
                      : std::string()));
    } catch (const std::exception& error) {
      throw InputError(where + ": skeletonization failed: " + error.what());
    }
  }
  CurveSkeleton result;
  const auto count = static_cast<Index>(boost::num_vertices(skeleton));
  if (count == 0) throw InputError(where + ": skeletonization produced no skeleton");
  result.points.resize(count, 3);
  result.owner = VectorXi::Constant(surface.vertices.rows(), -1);
  for (const auto k : CGAL::make_range(boost::vertices(skeleton))) {
    const Point& p = skeleton[k].point;
    result.points.row(static_cast<Index>(k)) << p.x(), p.y(), p.z();
    for (const auto v : skeleton[k].vertices)
      result.owner[static_cast<Index>(v.idx())] = static_cast<int>(k);
  }
  result.edges.resize(static_cast<Index>(boost::num_edges(skeleton)), 2);
  Index e = 0;
  for (const auto edge : CGAL::make_range(boost::edges(skeleton))) {
    result.edges(e, 0) = static_cast<int>(boost::source(edge, skeleton));
    result.edges(e, 1) = static_cast<int>(boost::target(edge, skeleton));
    ++e;
  }
  for (Index v = 0; v < result.owner.size(); ++v) {
    if (result.owner[v] >= 0) continue;
    double best = std::numeric_limits<double>::infinity();
    for (Index k = 0; k < count; ++k) {
      const double d = (result.points.row(k) - surface.vertices.row(v)).squaredNorm();
      if (d < best) {
        best = d;
        result.owner[v] = static_cast<int>(k);
      }
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

bool is_connected(const CurveSkeleton& skeleton) {
  const Index n = skeleton.points.rows();
  if (n == 0) return false;
  std::vector<std::vector<int>> next(n);
  for (Index e = 0; e < skeleton.edges.rows(); ++e) {
    next[skeleton.edges(e, 0)].push_back(skeleton.edges(e, 1));
    next[skeleton.edges(e, 1)].push_back(skeleton.edges(e, 0));
  }
  std::vector<char> seen(n, 0);
  std::vector<int> stack{0};
  seen[0] = 1;
  Index reached = 1;
  while (!stack.empty()) {
    const int k = stack.back();
    stack.pop_back();
    for (int j : next[k])
      if (!seen[j]) {
        seen[j] = 1;
        ++reached;
        stack.push_back(j);
      }
  }
  return reached == n;
}

}  // namespace strata
