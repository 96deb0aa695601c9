// CGAL unit (built in strata_meshing_cgal, see CMakeLists.txt).
#include "strata/meshing/surface_simplification.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/helpers.h>

#include <exception>
#include <new>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

}  // namespace

SurfaceMesh simplify_surface(const SurfaceMesh& surface, Index target_vertices,
                             const std::string& where) {
  if (target_vertices < 4)
    throw InputError(where + ": a closed surface needs at least 4 vertices, asked for " +
                     std::to_string(target_vertices));
  if (surface.vertices.rows() <= target_vertices) return surface;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> handles;
  handles.reserve(surface.vertices.rows());
  for (Index v = 0; v < surface.vertices.rows(); ++v)
    handles.push_back(mesh.add_vertex(
        Point(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2))));
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = surface.triangles(f, c);
      if (v < 0 || v >= surface.vertices.rows())
        throw InputError(where + ": triangle " + std::to_string(f) + " names vertex " +
                         std::to_string(v) + " of " + std::to_string(surface.vertices.rows()));
    }
    const auto face =
        mesh.add_face(handles[surface.triangles(f, 0)], handles[surface.triangles(f, 1)],
                      handles[surface.triangles(f, 2)]);
    if (face == Mesh::null_face())
      throw InputError(where + ": triangle " + std::to_string(f) +
                       " breaks the 2-manifold (simplification needs a closed manifold surface)");
  }
  if (!CGAL::is_closed(mesh))
    throw InputError(where + ": the surface has holes (simplification needs a closed surface)");
  // A closed connected genus-0 surface of V vertices has 3V − 6 edges; collapses stop as soon as
  // fewer than 3T − 5 edges are left, at T vertices.
  const std::size_t edges = static_cast<std::size_t>(3 * target_vertices - 5);
  CGAL::Surface_mesh_simplification::Count_stop_predicate<Mesh> stop(edges);
  try {
    CGAL::Surface_mesh_simplification::edge_collapse(mesh, stop);
  } catch (const std::bad_alloc&) {
    throw InputError(where + ": simplification ran out of memory");
  } catch (const std::exception& error) {
    throw InputError(where + ": simplification failed: " + error.what());
  }
  mesh.collect_garbage();

  SurfaceMesh result;
  result.vertices.resize(static_cast<Index>(mesh.number_of_vertices()), 3);
  for (const Mesh::Vertex_index v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    result.vertices.row(static_cast<Index>(v.idx())) << p.x(), p.y(), p.z();
  }
  result.triangles.resize(static_cast<Index>(mesh.number_of_faces()), 3);
  Index f = 0;
  for (const Mesh::Face_index face : mesh.faces()) {
    int c = 0;
    for (const Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(face), mesh))
      result.triangles(f, c++) = static_cast<int>(v.idx());
    ++f;
  }
  return result;
}

}  // namespace strata
