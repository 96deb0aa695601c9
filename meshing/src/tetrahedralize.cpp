// Option checks, the tet-count estimate and the post-processing shared by both Mesh_3 domains.
#include "strata/meshing/tetrahedralize.hpp"

#include <cmath>
#include <sstream>

#include "strata/core/common/error.hpp"
#include "tetrahedralize_detail.hpp"

namespace strata {

double estimate_tet_count(double volume, const MeshingOptions& options) {
  const double h = options.cell_size;
  return std::abs(volume) / (kTetsPerCellVolume * h * h * h);
}

void check_meshing_request(double volume, const MeshingOptions& options) {
  auto fail = [](const std::string& message) { throw InputError("meshing: " + message); };
  if (!(options.cell_size > 0.0) || !std::isfinite(options.cell_size)) {
    fail("cell_size must be > 0");
  }
  if (!(options.facet_size >= 0.0) || !(options.facet_distance >= 0.0)) {
    fail("facet_size and facet_distance must be >= 0 (0 selects the default)");
  }
  if (!(options.facet_angle > 0.0 && options.facet_angle <= 30.0)) {
    fail("facet_angle must be in (0, 30] degrees");
  }
  if (!(options.cell_radius_edge_ratio >= 2.0)) fail("cell_radius_edge_ratio must be >= 2");
  const double estimate = estimate_tet_count(volume, options);
  if (!(estimate <= options.max_tets)) {
    std::ostringstream message;
    message.precision(3);
    message << "cell_size " << options.cell_size << " would give about " << estimate
            << " tets for a volume of " << std::abs(volume) << " (limit " << options.max_tets
            << ", about 1 kB each): use a larger cell_size";
    fail(message.str());
  }
}

namespace detail {

MeshingOptions resolved_meshing_options(const MeshingOptions& options) {
  MeshingOptions resolved = options;
  if (resolved.facet_size == 0.0) resolved.facet_size = options.cell_size;
  if (resolved.facet_distance == 0.0) resolved.facet_distance = options.cell_size / 10.0;
  return resolved;
}

TetMesh finish_tet_mesh(TetMesh mesh, const std::string& what) {
  if (mesh.tets.rows() == 0) {
    throw InputError(what +
                     ": Mesh_3 produced no tets (is the domain empty or smaller than the "
                     "cell size?)");
  }
  remove_unreferenced_vertices(mesh);
  validate_tet_mesh(mesh, what);
  orient_tets(mesh);
  return mesh;
}

}  // namespace detail
}  // namespace strata
