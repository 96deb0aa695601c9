// Mesh_3 on an implicit domain { f < 0 } (Labeled_mesh_domain_3): the only translation unit that
// instantiates it.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_triangulation_3.h>

#include "mesh_3_common.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/tetrahedralize.hpp"
#include "tetrahedralize_detail.hpp"

namespace strata {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

/// Precision of the surface points Mesh_3 finds by bisection, relative to the box diagonal.
constexpr double kRelativeErrorBound = 1e-6;

}  // namespace

TetMesh tetrahedralize_implicit(const std::function<double(const Vector3d&)>& signed_distance,
                                const Vector3d& box_min, const Vector3d& box_max,
                                const MeshingOptions& options, double volume_estimate) {
  if (!((box_max - box_min).array() > 0.0).all()) {
    throw InputError("implicit domain: the bounding box is empty");
  }
  check_meshing_request(volume_estimate > 0.0 ? volume_estimate : (box_max - box_min).prod(),
                        options);
  const MeshingOptions resolved = detail::resolved_meshing_options(options);

  CGAL::get_default_random() = CGAL::Random(resolved.seed);
  CGAL::Random domain_random(resolved.seed);
  auto function = [&signed_distance](const Kernel::Point_3& p) {
    return Kernel::FT(signed_distance(Vector3d(p.x(), p.y(), p.z())));
  };
  const Kernel::Iso_cuboid_3 box(box_min(0), box_min(1), box_min(2), box_max(0), box_max(1),
                                 box_max(2));
  namespace p = CGAL::parameters;
  Domain domain = Domain::create_implicit_mesh_domain(
      function, box, p::relative_error_bound = kRelativeErrorBound, p::p_rng = &domain_random);
  const Criteria criteria = detail::make_mesh_criteria<Criteria>(resolved);
  const C3t3 c3t3 = detail::run_make_mesh_3<C3t3>(domain, criteria, resolved);
  return detail::finish_tet_mesh(detail::c3t3_to_tet_mesh(c3t3), "implicit mesh");
}

}  // namespace strata
