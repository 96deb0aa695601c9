#include "strata/core/sim/loads.hpp"

#include <Eigen/Geometry>

#include "strata/core/common/error.hpp"

namespace strata {

VectorXd gravity_forces(ConstRef<VectorXd> vertex_mass, const Vector3d& gravity) {
  VectorXd forces(3 * vertex_mass.size());
  for (Index v = 0; v < vertex_mass.size(); ++v)
    forces.segment<3>(3 * v) = vertex_mass[v] * gravity;
  return forces;
}

void add_region_force(const std::string& name, const std::vector<int>& vertices,
                      const Vector3d& total_force, ConstRef<MatrixX3d> positions,
                      ConstRef<MatrixX3i> boundary, VectorXd& forces) {
  if (vertices.empty()) throw InputError(name + ": region selects no vertex");
  std::vector<char> selected(positions.rows(), 0);
  for (int v : vertices)
    selected[v] = 1;

  std::vector<Index> faces;
  std::vector<double> areas;
  double area_sum = 0.0;
  for (Index f = 0; f < boundary.rows(); ++f) {
    if (!selected[boundary(f, 0)] || !selected[boundary(f, 1)] || !selected[boundary(f, 2)])
      continue;
    const Vector3d x0 = positions.row(boundary(f, 0)).transpose();
    const Vector3d x1 = positions.row(boundary(f, 1)).transpose();
    const Vector3d x2 = positions.row(boundary(f, 2)).transpose();
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    faces.push_back(f);
    areas.push_back(area);
    area_sum += area;
  }
  if (faces.empty() || !(area_sum > 0.0)) {
    const Vector3d share = total_force / static_cast<double>(vertices.size());
    for (int v : vertices)
      forces.segment<3>(3 * v) += share;
    return;
  }
  for (size_t k = 0; k < faces.size(); ++k) {
    const Vector3d corner_share = total_force * (areas[k] / area_sum / 3.0);
    for (int c = 0; c < 3; ++c)
      forces.segment<3>(3 * boundary(faces[k], c)) += corner_share;
  }
}

ExternalLoads external_loads(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                             ConstRef<VectorXd> vertex_mass, const Vector3d& gravity,
                             const std::vector<RegionLoad>& loads, double tolerance) {
  if (!gravity.allFinite()) throw InputError("gravity: must be finite");
  ExternalLoads result;
  result.base = gravity_forces(vertex_mass, gravity);
  for (const RegionLoad& load : loads) {
    validate_region(load.region, load.name + ".region");
    if (!load.total_force.allFinite()) throw InputError(load.name + ": total_force must be finite");
    validate_amplitude(load.amplitude, load.name + ".amplitude");
    VectorXd* target = &result.base;
    if (!load.amplitude.empty()) {
      result.timed.push_back({load.amplitude, VectorXd::Zero(result.base.size())});
      target = &result.timed.back().forces;
    }
    add_region_force(load.name, select_vertices(load.region, rest_positions, tolerance),
                     load.total_force, rest_positions, boundary, *target);
  }
  return result;
}

VectorXd external_forces(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX3i> boundary,
                         ConstRef<VectorXd> vertex_mass, const Vector3d& gravity,
                         const std::vector<RegionLoad>& loads, double tolerance) {
  ExternalLoads split =
      external_loads(rest_positions, boundary, vertex_mass, gravity, loads, tolerance);
  for (const TimedForces& timed : split.timed)
    split.base += timed.forces;
  return split.base;
}

}  // namespace strata
