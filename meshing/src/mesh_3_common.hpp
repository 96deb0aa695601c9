#pragma once
// Internal: Mesh_3 criteria, optimisation parameters and the C3T3 → TetMesh conversion, shared by
// the polyhedral and implicit translation units (each instantiates them once).
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>

#include <unordered_map>

#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/meshing/meshing_options.hpp"

namespace strata::detail {

/// Mesh_3 criteria from resolved options (edge_size = facet_size; used only with features).
template <typename Criteria>
Criteria make_mesh_criteria(const MeshingOptions& options) {
  namespace p = CGAL::parameters;
  return Criteria(p::edge_size = options.facet_size, p::facet_angle = options.facet_angle,
                  p::facet_size = options.facet_size, p::facet_distance = options.facet_distance,
                  p::cell_radius_edge_ratio = options.cell_radius_edge_ratio,
                  p::cell_size = options.cell_size);
}

/// Max iterations of ODT / Lloyd smoothing (bounded, so runs stay deterministic without a time
/// limit).
inline constexpr int kSmoothingIterations = 10;

/// make_mesh_3 with the optimisers of `options`, every time limit 0 (off) so the result does not
/// depend on the machine's speed. Reseed CGAL's default random generator before calling.
template <typename C3t3, typename Domain, typename Criteria>
C3t3 run_make_mesh_3(const Domain& domain, const Criteria& criteria,
                     const MeshingOptions& options) {
  namespace p = CGAL::parameters;
  return CGAL::make_mesh_3<C3t3>(
      domain, criteria,
      options.odt ? p::odt(p::time_limit = 0, p::max_iteration_number = kSmoothingIterations)
                  : p::no_odt(),
      options.lloyd ? p::lloyd(p::time_limit = 0, p::max_iteration_number = kSmoothingIterations)
                    : p::no_lloyd(),
      options.perturb ? p::perturb(p::time_limit = 0, p::sliver_bound = options.sliver_bound)
                      : p::no_perturb(),
      options.exude ? p::exude(p::time_limit = 0, p::sliver_bound = options.sliver_bound)
                    : p::no_exude());
}

/// The tets of the complex (cells_in_complex, in the triangulation's order) and the vertices they
/// use, numbered by first use.
template <typename C3t3>
TetMesh c3t3_to_tet_mesh(const C3t3& c3t3) {
  using Vertex_handle = typename C3t3::Vertex_handle;
  std::unordered_map<const void*, int> index;
  std::vector<Vertex_handle> used;
  TetMesh mesh;
  mesh.tets.resize(static_cast<Index>(c3t3.number_of_cells_in_complex()), 4);
  Index t = 0;
  for (auto cell = c3t3.cells_in_complex_begin(); cell != c3t3.cells_in_complex_end(); ++cell) {
    for (int k = 0; k < 4; ++k) {
      const Vertex_handle vertex = cell->vertex(k);
      const auto [it, inserted] = index.emplace(&*vertex, static_cast<int>(used.size()));
      if (inserted) used.push_back(vertex);
      mesh.tets(t, k) = it->second;
    }
    ++t;
  }
  mesh.vertices.resize(static_cast<Index>(used.size()), 3);
  for (std::size_t v = 0; v < used.size(); ++v) {
    const auto& point = used[v]->point();
    mesh.vertices.row(static_cast<Index>(v)) << CGAL::to_double(point.x()),
        CGAL::to_double(point.y()), CGAL::to_double(point.z());
  }
  return mesh;
}

}  // namespace strata::detail
