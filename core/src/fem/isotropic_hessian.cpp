#include "strata/core/fem/isotropic_hessian.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "strata/core/fem/material_registry.hpp"
#include "strata/core/fem/neohookean.hpp"

namespace strata {

namespace {

constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};

/// Division that keeps its sign and stays finite when the denominator vanishes (as corotated.cpp).
double safe_divide(double numerator, double denominator) {
  constexpr double kEpsilon = 1e-12;
  if (std::abs(denominator) < kEpsilon) denominator = denominator < 0.0 ? -kEpsilon : kEpsilon;
  return numerator / denominator;
}

/// Nearest PSD matrix to a symmetric 3 × 3 one; positive definite input (all leading minors > 0)
/// is returned unchanged.
Matrix3d project_symmetric_3x3(const Matrix3d& A) {
  const double minor2 = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  if (A(0, 0) > 0.0 && minor2 > 0.0 && A.determinant() > 0.0) return A;
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eigen(A);
  const Vector3d clamped = eigen.eigenvalues().cwiseMax(0.0);
  return eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace

/// StVK: Ψ̂ = μ Σ e_k² + λ/2 (Σ e_k)², e_k = (σ_k² − 1)/2, ψ_i = σ_i (2μ e_i + λ tr E).
void stvk_singular_frame(const Vector3d& s, const LameParameters& lame, SingularFrameHessian& h) {
  const double mu = lame.mu, lambda = lame.lambda;
  Vector3d e;
  for (int k = 0; k < 3; ++k)
    e[k] = 0.5 * (s[k] * s[k] - 1.0);
  const double trace = e.sum();
  h.sigma_hessian = lambda * s * s.transpose();
  for (int k = 0; k < 3; ++k)
    h.sigma_hessian(k, k) += 2.0 * mu * e[k] + lambda * trace + 2.0 * mu * s[k] * s[k];
  const double shift = lambda * trace - mu;
  for (int p = 0; p < 3; ++p) {
    const double si = s[kPairs[p][0]], sj = s[kPairs[p][1]];
    const double squares = si * si + sj * sj;
    h.flip[p] = mu * (squares + si * sj) + shift;
    h.twist[p] = mu * (squares - si * sj) + shift;
  }
}

/// Stable neo-Hookean: ψ_i = c σ_i + λ'(J − α) ∂J/∂σ_i with c = μ'(1 − 1/(I_C + 1)), J = σ₀σ₁σ₂.
void neohookean_singular_frame(const Vector3d& s, const LameParameters& lame,
                               SingularFrameHessian& h) {
  const NeoHookeanConstants k = neohookean_constants(lame);
  const double Ic = s.squaredNorm();
  const double J = s[0] * s[1] * s[2];
  const double c = k.mu * (1.0 - 1.0 / (Ic + 1.0));
  const double volume_term = k.lambda * (J - k.alpha);
  const Vector3d dJ(s[1] * s[2], s[0] * s[2], s[0] * s[1]);
  h.sigma_hessian =
      (2.0 * k.mu / ((Ic + 1.0) * (Ic + 1.0))) * s * s.transpose() + k.lambda * dJ * dJ.transpose();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      h.sigma_hessian(i, j) += i == j ? c : volume_term * s[3 - i - j];
  for (int p = 0; p < 3; ++p) {
    const double third = s[3 - kPairs[p][0] - kPairs[p][1]];
    h.flip[p] = c - volume_term * third;
    h.twist[p] = c + volume_term * third;
  }
}

/// Corotated: ψ_i = 2μ(σ_i − 1) + λ(Σσ − 3); the twist divides as d2psi_corotated_dF2 does.
void corotated_singular_frame(const Vector3d& s, const LameParameters& lame,
                              SingularFrameHessian& h) {
  const double trace_term = s.sum() - 3.0;
  Vector3d dpsi;
  for (int i = 0; i < 3; ++i)
    dpsi[i] = 2.0 * lame.mu * (s[i] - 1.0) + lame.lambda * trace_term;
  h.sigma_hessian = Matrix3d::Constant(lame.lambda);
  h.sigma_hessian.diagonal().array() += 2.0 * lame.mu;
  for (int p = 0; p < 3; ++p) {
    const int i = kPairs[p][0], j = kPairs[p][1];
    h.flip[p] = 2.0 * lame.mu;
    h.twist[p] = safe_divide(dpsi[i] + dpsi[j], s[i] + s[j]);
  }
}

SingularFrameHessian singular_frame_hessian(MaterialModel model, const Matrix3d& F,
                                            const LameParameters& lame) {
  SingularFrameHessian h;
  h.svd = rotation_variant_svd(F);
  material_traits(model).singular_frame(h.svd.sigma, lame, h);
  return h;
}

Matrix9d frame_hessian_matrix(const SingularFrameHessian& h, bool project_psd) {
  const Matrix3d& U = h.svd.U;
  const Matrix3d& V = h.svd.V;
  const Matrix3d A = project_psd ? project_symmetric_3x3(h.sigma_hessian) : h.sigma_hessian;
  // H = Σ_k left_k right_kᵀ over nine rank-one terms, in plain arrays (Eigen would route these
  // small products through its GEMM kernel). Terms 0–2: right_i = vec(u_i v_iᵀ) (the stretch
  // directions, vec(M)[3c + r] = M(r, c)), left_i = Σ_j A_ij right_j. Terms 3–8, per pair (i, j):
  // vec(u_i v_jᵀ ± u_j v_iᵀ) (flip +, twist −), weighted by half the eigenvalue (the √2 norm).
  double left[9][9], right[9][9];
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        right[i][3 * c + r] = U(r, i) * V(c, i);
  for (int i = 0; i < 3; ++i)
    for (int e = 0; e < 9; ++e)
      left[i][e] = A(i, 0) * right[0][e] + A(i, 1) * right[1][e] + A(i, 2) * right[2][e];
  for (int p = 0; p < 3; ++p) {
    const int i = kPairs[p][0], j = kPairs[p][1];
    const double flip = 0.5 * (project_psd ? std::max(h.flip[p], 0.0) : h.flip[p]);
    const double twist = 0.5 * (project_psd ? std::max(h.twist[p], 0.0) : h.twist[p]);
    double* plus = right[3 + 2 * p];
    double* minus = right[4 + 2 * p];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) {
        const double ij = U(r, i) * V(c, j), ji = U(r, j) * V(c, i);
        plus[3 * c + r] = ij + ji;
        minus[3 * c + r] = ij - ji;
      }
    for (int e = 0; e < 9; ++e) {
      left[3 + 2 * p][e] = flip * plus[e];
      left[4 + 2 * p][e] = twist * minus[e];
    }
  }
  Matrix9d H;
  for (int col = 0; col < 9; ++col)
    for (int row = 0; row < 9; ++row) {
      double sum = 0.0;
      for (int k = 0; k < 9; ++k)
        sum += left[k][row] * right[k][col];
      H(row, col) = sum;
    }
  return H;
}

Matrix9d d2psi_dF2_psd(MaterialModel model, const Matrix3d& F, const LameParameters& lame) {
  return frame_hessian_matrix(singular_frame_hessian(model, F, lame), true);
}

}  // namespace strata
