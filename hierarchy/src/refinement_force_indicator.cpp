#include "strata/hierarchy/refinement_force_indicator.hpp"

#include <algorithm>
#include <cmath>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

// Faces of a positively oriented tet; face k is opposite vertex k.
constexpr int kOppositeFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

double triangle_area(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

struct ForceParts {
  VectorXd areas;  // c_v
  VectorXd loads;  // g_v
  ForceReference reference;
};

}  // namespace

ForceIndicator::ForceIndicator(double stress_floor) : m_stress_floor(stress_floor) {
  if (!(stress_floor > 0.0) || !std::isfinite(stress_floor))
    throw InputError("ForceIndicator: stress_floor must be a positive number");
}

VectorXd ForceIndicator::vertex_force_areas(ConstRef<MatrixX4i> tets,
                                            ConstRef<VectorXd> positions) {
  VectorXd areas = VectorXd::Zero(positions.size() / 3);
  for (Index t = 0; t < tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int* f = kOppositeFaces[k];
      const double area = triangle_area(positions.segment<3>(3 * tets(t, f[0])),
                                        positions.segment<3>(3 * tets(t, f[1])),
                                        positions.segment<3>(3 * tets(t, f[2])));
      areas[tets(t, k)] += area / 3.0;
    }
  return areas;
}

VectorXd ForceIndicator::localised_loads(ConstRef<VectorXd> external_forces,
                                         ConstRef<VectorXd> vertex_mass) {
  Vector3d total = Vector3d::Zero();
  for (Index v = 0; v < vertex_mass.size(); ++v)
    total += external_forces.segment<3>(3 * v);
  const double mass = vertex_mass.sum();
  const Vector3d mean_acceleration = mass > 0.0 ? Vector3d(total / mass) : Vector3d::Zero();
  VectorXd loads(external_forces.size());
  for (Index v = 0; v < vertex_mass.size(); ++v)
    loads.segment<3>(3 * v) =
        external_forces.segment<3>(3 * v) - vertex_mass[v] * mean_acceleration;
  return loads;
}

double ForceIndicator::body_surface_area(const TetTree& tree) {
  MatrixX4i roots(tree.num_roots(), 4);
  for (Index r = 0; r < tree.num_roots(); ++r) {
    const std::array<int, 4> v = tree.tet_vertices(static_cast<NodeId>(r));
    roots.row(r) << v[0], v[1], v[2], v[3];
  }
  const MatrixX3i boundary = boundary_faces(roots);
  double area = 0.0;
  for (Index f = 0; f < boundary.rows(); ++f)
    area +=
        triangle_area(tree.vertex_position(boundary(f, 0)), tree.vertex_position(boundary(f, 1)),
                      tree.vertex_position(boundary(f, 2)));
  return area;
}

double ForceIndicator::cached_surface_area(const TetTree& tree) const {
  double checksum = 0.0;
  for (Index v = 0; v < tree.num_coarse_vertices(); ++v)
    checksum += static_cast<double>(v % 7 + 1) * tree.vertex_position(static_cast<int>(v)).sum();
  const std::lock_guard<std::mutex> lock(m_cache_mutex);
  if (m_cache.tree != &tree || m_cache.num_roots != tree.num_roots() ||
      m_cache.checksum != checksum)
    m_cache = {&tree, tree.num_roots(), checksum, body_surface_area(tree)};
  return m_cache.area;
}

namespace {

ForceParts force_parts(const CutState& state, double stress_floor, double surface) {
  const Index num_vertices = state.flat.mesh.vertices.rows();
  STRATA_VERIFY(state.positions.size() == 3 * num_vertices &&
                    state.external_forces.size() == 3 * num_vertices &&
                    state.vertex_mass.size() == num_vertices &&
                    state.fields.cauchy_stress.rows() == state.flat.mesh.tets.rows(),
                "ForceIndicator: CutState arrays do not match the flattened cut");
  ForceParts parts;
  parts.areas = ForceIndicator::vertex_force_areas(state.flat.mesh.tets, state.positions);
  parts.loads = ForceIndicator::localised_loads(state.external_forces, state.vertex_mass);
  double load_sum = 0.0;
  for (Index v = 0; v < num_vertices; ++v)
    if (parts.areas[v] > 0.0)
      load_sum += parts.loads.segment<3>(3 * v).squaredNorm() / parts.areas[v];
  ForceReference& ref = parts.reference;
  ref.stress_rms = volume_rms_stress(state);
  ref.load_rms = surface > 0.0 ? std::sqrt(load_sum / surface) : 0.0;
  ref.floor = stress_floor * state.material.youngs_modulus;
  ref.scale = std::max({ref.stress_rms, ref.load_rms, ref.floor});
  return parts;
}

}  // namespace

ForceReference ForceIndicator::reference(const CutState& state) const {
  return force_parts(state, m_stress_floor, cached_surface_area(state.tree)).reference;
}

void ForceIndicator::evaluate(const CutState& state, VectorXd& eta) const {
  const ForceParts parts = force_parts(state, m_stress_floor, cached_surface_area(state.tree));
  const MatrixX4i& tets = state.flat.mesh.tets;
  const VectorXd* traction = state.finest_load_traction;
  STRATA_VERIFY(!traction || traction->size() == tets.rows(),
                "ForceIndicator: finest_load_traction must have one entry per flat tet");
  eta.resize(tets.rows());
  for (Index t = 0; t < tets.rows(); ++t) {
    double density = voigt_frobenius_norm(state.fields.cauchy_stress.row(t).transpose());
    for (int k = 0; k < 4; ++k) {
      const int v = tets(t, k);
      if (parts.areas[v] > 0.0)
        density = std::max(density, parts.loads.segment<3>(3 * v).norm() / parts.areas[v]);
    }
    if (traction) density = std::max(density, (*traction)[t]);
    eta[t] = density / parts.reference.scale;
  }
}

}  // namespace strata
