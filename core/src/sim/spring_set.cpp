#include "strata/core/sim/spring_set.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace strata {

double SpringSet::energy(ConstRef<VectorXd> x) const {
  double energy = 0.0;
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const double stretch = (x.segment<3>(3 * b) - x.segment<3>(3 * a)).norm() - rest[s];
    energy += 0.5 * stiffness[s] * stretch * stretch;
  }
  return energy;
}

void SpringSet::add_forces(ConstRef<VectorXd> x, VectorXd& f, double scale) const {
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const Vector3d d = x.segment<3>(3 * b) - x.segment<3>(3 * a);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Vector3d force = scale * stiffness[s] * (length - rest[s]) / length * d;
    f.segment<3>(3 * a) += force;
    f.segment<3>(3 * b) -= force;
  }
}

namespace {

/// Entry k = 9 block + 3 c + r of a spring's Hessian: block 0..3 = (a, a), (b, b), (a, b), (b, a),
/// row r and column c within the block; its row and column in the matrix.
std::array<Index, 2> entry_position(int a, int b, int k) {
  const int block = k / 9, c = (k % 9) / 3, r = k % 3;
  const int row_vertex = (block == 0 || block == 2) ? a : b;
  const int column_vertex = (block == 0 || block == 3) ? a : b;
  return {3 * row_vertex + r, 3 * column_vertex + c};
}

}  // namespace

bool SpringSet::locate(const SparseMatrixd& hessian) const {
  m_offsets.resize(36 * edges.size());
  const int* outer = hessian.outerIndexPtr();
  const int* inner = hessian.innerIndexPtr();
  for (std::size_t s = 0; s < edges.size(); ++s)
    for (int k = 0; k < 36; ++k) {
      const auto [row, column] = entry_position(edges[s][0], edges[s][1], k);
      const int* begin = inner + outer[column];
      const int* end =
          inner + (hessian.isCompressed() ? outer[column + 1]
                                          : outer[column] + hessian.innerNonZeroPtr()[column]);
      const int* found = std::lower_bound(begin, end, static_cast<int>(row));
      if (found == end || *found != row) return false;
      m_offsets[36 * s + k] = static_cast<int>(found - inner);
    }
  return true;
}

void SpringSet::add_hessian(ConstRef<VectorXd> x, SparseMatrixd& hessian, bool project_psd) const {
  // The cached offsets belong to this pattern if every entry lies at its row inside its column.
  const auto in_place = [&](std::size_t s, int k) {
    const int offset = m_offsets[36 * s + k];
    const auto [row, column] = entry_position(edges[s][0], edges[s][1], k);
    const int* outer = hessian.outerIndexPtr();
    const int end = hessian.isCompressed() ? outer[column + 1]
                                           : outer[column] + hessian.innerNonZeroPtr()[column];
    return offset >= outer[column] && offset < end && hessian.innerIndexPtr()[offset] == row;
  };
  bool cached = m_offsets.size() == 36 * edges.size();
  for (std::size_t s = 0; cached && s < edges.size(); ++s)
    for (int k = 0; cached && k < 36; ++k)
      cached = in_place(s, k);
  if (!cached && !locate(hessian)) {
    // Not every entry is in the pattern: insert them.
    for (Index s = 0; s < size(); ++s)
      for (int k = 0; k < 36; ++k) {
        const auto [row, column] = entry_position(edges[s][0], edges[s][1], k);
        hessian.coeffRef(row, column) += 0.0;
      }
    hessian.makeCompressed();
    m_offsets.clear();
    if (!locate(hessian)) throw std::logic_error("SpringSet::add_hessian: pattern");
  }
  double* values = hessian.valuePtr();
  for (Index s = 0; s < size(); ++s) {
    const auto [a, b] = edges[s];
    const Vector3d d = x.segment<3>(3 * b) - x.segment<3>(3 * a);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Vector3d n = d / length;
    double transverse = 1.0 - rest[s] / length;
    if (project_psd) transverse = std::max(transverse, 0.0);
    const Matrix3d nn = n * n.transpose();
    const Matrix3d K = stiffness[s] * (nn + transverse * (Matrix3d::Identity() - nn));
    const int* offset = &m_offsets[36 * s];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) {
        const double k = K(r, c);
        values[offset[3 * c + r]] += k;
        values[offset[9 + 3 * c + r]] += k;
        values[offset[18 + 3 * c + r]] -= k;
        values[offset[27 + 3 * c + r]] -= k;
      }
  }
}

void SpringSet::add_pattern(std::vector<Eigen::Triplet<double>>& triplets) const {
  for (const auto& [a, b] : edges)
    for (int i : {a, b})
      for (int j : {a, b})
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            triplets.emplace_back(3 * i + r, 3 * j + c, 0.0);
}

}  // namespace strata
