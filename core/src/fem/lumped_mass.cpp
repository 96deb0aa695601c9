#include "strata/core/fem/lumped_mass.hpp"

namespace strata {

VectorXd lumped_vertex_mass(ConstRef<VectorXd> rest_volume, ConstRef<MatrixX4i> tets,
                            Index num_vertices, double density) {
  VectorXd mass = VectorXd::Zero(num_vertices);
  for (Index t = 0; t < tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      mass[tets(t, k)] += 0.25 * density * rest_volume[t];
  return mass;
}

VectorXd per_dof_mass(ConstRef<VectorXd> vertex_mass) {
  VectorXd mass(3 * vertex_mass.size());
  for (Index v = 0; v < vertex_mass.size(); ++v)
    mass.segment<3>(3 * v).setConstant(vertex_mass[v]);
  return mass;
}

}  // namespace strata
