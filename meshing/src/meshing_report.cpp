#include "strata/meshing/meshing_report.hpp"

#include <cmath>
#include <cstdio>

namespace strata {

SurfaceReport describe_surface(const SurfaceMesh& surface) {
  SurfaceReport report;
  report.vertices = surface.vertices.rows();
  report.triangles = surface.triangles.rows();
  report.topology = surface_topology(surface);
  report.closed = report.topology.boundary_edges == 0 && report.topology.non_manifold_edges == 0 &&
                  report.triangles > 0;
  report.enclosed_volume = std::abs(enclosed_volume(surface));
  if (report.vertices > 0) {
    report.bbox_min = surface.vertices.colwise().minCoeff().transpose();
    report.bbox_max = surface.vertices.colwise().maxCoeff().transpose();
  }
  return report;
}

std::string format_surface_report(const SurfaceReport& report) {
  const SurfaceTopology& topology = report.topology;
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "vertices          %lld\n"
                "triangles         %lld\n"
                "closed            %s (%lld boundary edges)\n"
                "manifold          %s (%lld non-manifold edges)\n"
                "misoriented edges %lld\n"
                "degenerate        %lld triangles\n"
                "bounding box      [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]\n"
                "enclosed volume   %.6g%s\n",
                static_cast<long long>(report.vertices), static_cast<long long>(report.triangles),
                report.closed ? "yes" : "no", static_cast<long long>(topology.boundary_edges),
                topology.non_manifold_edges == 0 ? "yes" : "no",
                static_cast<long long>(topology.non_manifold_edges),
                static_cast<long long>(topology.misoriented_edges),
                static_cast<long long>(topology.degenerate_triangles), report.bbox_min.x(),
                report.bbox_min.y(), report.bbox_min.z(), report.bbox_max.x(), report.bbox_max.y(),
                report.bbox_max.z(), report.enclosed_volume,
                report.closed ? "" : " (surface not closed: not a volume)");
  return buffer;
}

std::string format_meshing_report(const MeshingReport& report) {
  char buffer[512];
  if (report.from_cache) {
    std::snprintf(buffer, sizeof(buffer), "meshing           %s, from the cache\n",
                  report.route.c_str());
  } else {
    std::snprintf(buffer, sizeof(buffer), "meshing           %s, %.3g s\n", report.route.c_str(),
                  report.seconds);
  }
  std::string text = buffer;
  if (report.surface_volume > 0.0) {
    std::snprintf(buffer, sizeof(buffer), "surface volume    %.6g (tet / surface volume %.6f)\n",
                  report.surface_volume, report.volume_ratio());
    text += buffer;
  }
  return text + format_mesh_quality(report.quality);
}

}  // namespace strata
