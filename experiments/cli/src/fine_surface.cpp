#include "strata/app/fine_surface.hpp"

#include <chrono>

namespace strata::app {

FineSurface::FineSurface(SurfaceMesh surface, const TetMesh& rest_mesh)
    : m_surface(std::move(surface)),
      m_mesh_vertices(rest_mesh.vertices.rows()),
      m_mesh_tets(rest_mesh.tets.rows()) {
  const auto start = std::chrono::steady_clock::now();
  m_binding = bind_surface(rest_mesh, m_surface.vertices);
  m_offset = displacement_map(rest_mesh, m_surface.vertices).offset;
  m_bind_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool FineSurface::matches(const TetMesh& mesh) const {
  return mesh.vertices.rows() == m_mesh_vertices && mesh.tets.rows() == m_mesh_tets;
}

MatrixX3d FineSurface::positions(ConstRef<VectorXd> mesh_positions) const {
  return deformed_surface(m_binding, mesh_positions);
}

VtuFields FineSurface::fields(ConstRef<MatrixX3d> positions) const {
  VtuFields fields;
  fields.add_point_data("displacement", Eigen::MatrixXd(positions - m_surface.vertices));
  fields.add_point_data("displacement_map", Eigen::MatrixXd(m_offset));
  return fields;
}

double FineSurface::max_outside_distance() const {
  return m_binding.distance.size() > 0 ? m_binding.distance.maxCoeff() : 0.0;
}

}  // namespace strata::app
