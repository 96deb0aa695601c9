// Mesh_3 on a polyhedral domain (with optional sharp features): the only translation unit that
// instantiates it (about 45 CPU-s and 3 GB to compile).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <optional>
#include <vector>

#include "mesh_3_common.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/tetrahedralize.hpp"
#include "tetrahedralize_detail.hpp"

namespace strata {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Mesh_polyhedron_3<Kernel>::type;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index,
                                                     Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

/// The surface without degenerate triangles as a CGAL polyhedron; empty when it is not a closed
/// polygon mesh (open, non-manifold or inconsistently oriented).
std::optional<Polyhedron> closed_polyhedron(const SurfaceMesh& input) {
  SurfaceMesh surface = input;
  remove_degenerate_triangles(surface);
  std::vector<Kernel::Point_3> points;
  points.reserve(static_cast<std::size_t>(surface.vertices.rows()));
  for (Index v = 0; v < surface.vertices.rows(); ++v) {
    points.emplace_back(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2));
  }
  std::vector<std::array<std::size_t, 3>> triangles;
  triangles.reserve(static_cast<std::size_t>(surface.triangles.rows()));
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    triangles.push_back({static_cast<std::size_t>(surface.triangles(f, 0)),
                         static_cast<std::size_t>(surface.triangles(f, 1)),
                         static_cast<std::size_t>(surface.triangles(f, 2))});
  }
  namespace pmp = CGAL::Polygon_mesh_processing;
  if (triangles.empty() || !pmp::is_polygon_soup_a_polygon_mesh(triangles)) return std::nullopt;
  Polyhedron polyhedron;
  pmp::polygon_soup_to_polygon_mesh(points, triangles, polyhedron);
  if (!CGAL::is_closed(polyhedron)) return std::nullopt;
  return polyhedron;
}

}  // namespace

bool is_closed_manifold_surface(const SurfaceMesh& surface) {
  return closed_polyhedron(surface).has_value();
}

TetMesh tetrahedralize_surface(const SurfaceMesh& surface, const MeshingOptions& options) {
  if (surface.triangles.rows() > 0 && (surface.triangles.minCoeff() < 0 ||
                                       surface.triangles.maxCoeff() >= surface.vertices.rows())) {
    throw InputError("surface: a triangle refers to a vertex index out of range");
  }
  std::optional<Polyhedron> polyhedron = closed_polyhedron(surface);
  if (!polyhedron) {
    throw InputError(
        "surface is not a closed manifold (open, non-manifold or inconsistently "
        "oriented): mesh it through a level set");
  }
  check_meshing_request(enclosed_volume(surface), options);
  const MeshingOptions resolved = detail::resolved_meshing_options(options);

  CGAL::get_default_random() = CGAL::Random(resolved.seed);
  CGAL::Random domain_random(resolved.seed);
  Domain domain(*polyhedron, &domain_random);
  if (resolved.sharp_features) domain.detect_features(resolved.feature_angle);
  const Criteria criteria = detail::make_mesh_criteria<Criteria>(resolved);
  const C3t3 c3t3 = detail::run_make_mesh_3<C3t3>(domain, criteria, resolved);
  return detail::finish_tet_mesh(detail::c3t3_to_tet_mesh(c3t3), "surface mesh");
}

}  // namespace strata
