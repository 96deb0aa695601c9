#pragma once
/// \file tet_rest_data.hpp
/// Per-tet rest data computed once and stored contiguously: Dm⁻¹ and rest volume.
#include <vector>

#include "strata/core/common/types.hpp"

namespace strata {

struct TetRestData {
  /// Dm⁻¹ per tet, Dm = [X1−X0, X2−X0, X3−X0] at rest; #T entries.
  std::vector<Matrix3d> Dm_inv;
  /// Rest volume per tet [m³]; #T entries, all > 0.
  VectorXd rest_volume;
};

/// Computes the rest data of positively oriented, non-degenerate tets (see `validate_tet_mesh`,
/// `orient_tets`). Throws InputError naming the first tet that is inverted or degenerate.
TetRestData compute_tet_rest_data(ConstRef<MatrixX3d> rest_positions, ConstRef<MatrixX4i> tets);

}  // namespace strata
