#pragma once
// Internal to elastic_model.cpp: element stiffnesses in closed form — StVK and stable
// neo-Hookean, of one tet and of kLanes tets at once in structure-of-arrays form (vectorised
// across tets, like batched_stress_kernels.hpp) — and their scatter into the values of the fixed
// sparsity pattern.
#include "batched_stress_kernels.hpp"
#include "strata/core/fem/neohookean.hpp"
#include "strata/core/fem/stvk.hpp"

namespace strata::detail {

/// Stable neo-Hookean element stiffness in closed form. Its ∂²ψ/∂F² (neohookean.cpp) is
/// c₁ I + c₂ f fᵀ + λ g gᵀ + λ(J − α) ∂²J/∂F² with f = vec F, g = vec cof F, c₁ = μ(1 − 1/(I_C +
/// 1)), c₂ = 2μ/(I_C + 1)² (the model's μ, λ, α); contracted with g_a = ∇N_a, g_b = ∇N_b, block (a,
/// b) = ∂²W/∂x_a∂x_b is V [c₁ (g_a · g_b) I + c₂ (F g_a)(F g_b)ᵀ + λ (cof F g_a)(cof F g_b)ᵀ
/// + λ(J − α) E(F (g_a × g_b))], E(v)_qr = ε_qrk v_k (∂²J/∂F_qc∂F_rd = ε_qrk ε_cdl F_kl).
inline void neohookean_stiffness_blocks(const Matrix3d& F,
                                        const Eigen::Matrix<double, 4, 3>& grad_N,
                                        const LameParameters& lame, double volume,
                                        Matrix3d (&blocks)[4][4]) {
  const NeoHookeanConstants k = neohookean_constants(lame);
  const double Ic = F.squaredNorm();
  const Matrix3d G = cofactor_matrix(F);
  const double J = F.col(0).dot(G.col(0));
  const double c1 = volume * k.mu * (1.0 - 1.0 / (Ic + 1.0));
  const double c2 = volume * 2.0 * k.mu / ((Ic + 1.0) * (Ic + 1.0));
  const double c3 = volume * k.lambda;
  const double c4 = volume * k.lambda * (J - k.alpha);
  double g[4][3], Fg[4][3], Gg[4][3];
  for (int a = 0; a < 4; ++a)
    for (int r = 0; r < 3; ++r) {
      g[a][r] = grad_N(a, r);
      Fg[a][r] = F(r, 0) * grad_N(a, 0) + F(r, 1) * grad_N(a, 1) + F(r, 2) * grad_N(a, 2);
      Gg[a][r] = G(r, 0) * grad_N(a, 0) + G(r, 1) * grad_N(a, 1) + G(r, 2) * grad_N(a, 2);
    }
  for (int a = 0; a < 4; ++a)
    for (int b = a; b < 4; ++b) {
      const double gg = c1 * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
      const double n[3] = {g[a][1] * g[b][2] - g[a][2] * g[b][1],
                           g[a][2] * g[b][0] - g[a][0] * g[b][2],
                           g[a][0] * g[b][1] - g[a][1] * g[b][0]};
      double v[3];
      for (int r = 0; r < 3; ++r)
        v[r] = c4 * (F(r, 0) * n[0] + F(r, 1) * n[1] + F(r, 2) * n[2]);
      const double E[3][3] = {{0.0, v[2], -v[1]}, {-v[2], 0.0, v[0]}, {v[1], -v[0], 0.0}};
      for (int q = 0; q < 3; ++q)
        for (int r = 0; r < 3; ++r) {
          const double value =
              c2 * Fg[a][q] * Fg[b][r] + c3 * Gg[a][q] * Gg[b][r] + E[q][r] + (q == r ? gg : 0.0);
          blocks[a][b](q, r) = value;
          blocks[b][a](r, q) = value;
        }
    }
}

/// StVK element stiffness in closed form, block (b, a) = ∂²W/∂x_b∂x_a:
/// V [(g_aᵀ S g_b) I + λ (F g_b)(F g_a)ᵀ + μ (g_a · g_b) F Fᵀ + μ (F g_a)(F g_b)ᵀ], g_k = ∇N_k.
/// Plain scalar arrays on purpose: mixing Eigen's packed 3 × 3 temporaries with scalar diagonal
/// updates caused store-forwarding stalls that took half of the assembly time.
inline void stvk_stiffness_blocks(const Matrix3d& F, const Eigen::Matrix<double, 4, 3>& grad_N,
                                  const LameParameters& lame, double volume,
                                  Matrix3d (&blocks)[4][4]) {
  const Matrix3d S = second_piola_stvk(F, lame);
  double Fg[4][3], Sg[4][3], FFt[3][3];
  for (int k = 0; k < 4; ++k)
    for (int r = 0; r < 3; ++r) {
      Fg[k][r] = F(r, 0) * grad_N(k, 0) + F(r, 1) * grad_N(k, 1) + F(r, 2) * grad_N(k, 2);
      Sg[k][r] = S(r, 0) * grad_N(k, 0) + S(r, 1) * grad_N(k, 1) + S(r, 2) * grad_N(k, 2);
    }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      FFt[r][c] = F(r, 0) * F(c, 0) + F(r, 1) * F(c, 1) + F(r, 2) * F(c, 2);
  const double lambda = volume * lame.lambda, mu = volume * lame.mu;
  for (int b = 0; b < 4; ++b)
    for (int a = b; a < 4; ++a) {
      const double geometric =
          volume * (grad_N(a, 0) * Sg[b][0] + grad_N(a, 1) * Sg[b][1] + grad_N(a, 2) * Sg[b][2]);
      const double gg = mu * (grad_N(a, 0) * grad_N(b, 0) + grad_N(a, 1) * grad_N(b, 1) +
                              grad_N(a, 2) * grad_N(b, 2));
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          const double value = lambda * Fg[b][r] * Fg[a][c] + mu * Fg[a][r] * Fg[b][c] +
                               gg * FFt[r][c] + (r == c ? geometric : 0.0);
          blocks[b][a](r, c) = value;
          blocks[a][b](c, r) = value;
        }
    }
}

/// The lanes' F and shape-function gradients g_k = ∇N_k (g_k = row k − 1 of Dm⁻¹ for k ≥ 1,
/// g_0 = −g_1 − g_2 − g_3), `lane_Dm_inv` in the layout of lane_deformation_gradient.
inline void load_lane_element(const double (&lane_F)[3][3][kLanes], const double* lane_Dm_inv,
                              Vec (&F)[3][3], Vec (&g)[4][3]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      F[r][c] = load_vec(lane_F[r][c]);
  for (int k = 1; k < 4; ++k)
    for (int d = 0; d < 3; ++d)
      g[k][d] = load_vec(lane_Dm_inv + (3 * d + k - 1) * kLanes);
  for (int d = 0; d < 3; ++d)
    g[0][d] = -(g[1][d] + g[2][d] + g[3][d]);
}

/// StVK element stiffness of each lane l, 12 × 12 column-major: K[l][3b + c][3a + r] = K_ab(r, c),
/// K_ab = V [(g_aᵀ S g_b) I + λ (F g_a)(F g_b)ᵀ + μ (g_a · g_b) F Fᵀ + μ (F g_b)(F g_a)ᵀ],
/// g_k = ∇N_k (g_k = row k − 1 of Dm⁻¹ for k ≥ 1, g_0 = −g_1 − g_2 − g_3), S the second Piola
/// stress. `lane_Dm_inv` in the layout of lane_deformation_gradient.
struct StvkStiffnessLanes {
  double mu, lambda;
  explicit StvkStiffnessLanes(const LameParameters& lame) : mu(lame.mu), lambda(lame.lambda) {}

  void operator()(const double (&lane_F)[3][3][kLanes], const double* lane_Dm_inv,
                  const double* lane_volume, double (&K)[kLanes][12][12]) const {
    const Vec volume = load_vec(lane_volume);
    Vec F[3][3], g[4][3];
    load_lane_element(lane_F, lane_Dm_inv, F, g);

    Vec E[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = a; b < 3; ++b) {
        E[a][b] = 0.5 * (F[0][a] * F[0][b] + F[1][a] * F[1][b] + F[2][a] * F[2][b]);
        if (a == b) E[a][b] -= 0.5;
        E[b][a] = E[a][b];
      }
    const Vec lambda_trace = lambda * (E[0][0] + E[1][1] + E[2][2]);
    Vec S[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        S[a][b] = 2.0 * mu * E[a][b] + (a == b ? lambda_trace : Vec{});
    // Fg = F g_k, VFg = V F g_k, VSg = V S g_k, FFt = F Fᵀ.
    Vec Fg[4][3], VFg[4][3], VSg[4][3], FFt[3][3];
    for (int k = 0; k < 4; ++k)
      for (int r = 0; r < 3; ++r) {
        Fg[k][r] = F[r][0] * g[k][0] + F[r][1] * g[k][1] + F[r][2] * g[k][2];
        VFg[k][r] = volume * Fg[k][r];
        VSg[k][r] = volume * (S[r][0] * g[k][0] + S[r][1] * g[k][1] + S[r][2] * g[k][2]);
      }
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) {
        FFt[r][c] = F[r][0] * F[c][0] + F[r][1] * F[c][1] + F[r][2] * F[c][2];
        FFt[c][r] = FFt[r][c];
      }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b <= a; ++b) {
        const Vec geometric = g[a][0] * VSg[b][0] + g[a][1] * VSg[b][1] + g[a][2] * VSg[b][2];
        const Vec gg = (mu * volume) * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) {
            Vec value = lambda * VFg[a][r] * Fg[b][c] + mu * VFg[b][r] * Fg[a][c] + gg * FFt[r][c];
            if (r == c) value += geometric;
            for (int l = 0; l < kLanes; ++l) {
              K[l][3 * b + c][3 * a + r] = value[l];
              if (a != b) K[l][3 * a + r][3 * b + c] = value[l];
            }
          }
      }
  }
};

/// Stable neo-Hookean element stiffness of each lane l, in the layout of StvkStiffnessLanes:
/// neohookean_stiffness_blocks four tets at a time.
struct NeoHookeanStiffnessLanes {
  NeoHookeanConstants k;
  explicit NeoHookeanStiffnessLanes(const LameParameters& lame) : k(neohookean_constants(lame)) {}

  void operator()(const double (&lane_F)[3][3][kLanes], const double* lane_Dm_inv,
                  const double* lane_volume, double (&K)[kLanes][12][12]) const {
    const Vec volume = load_vec(lane_volume);
    Vec F[3][3], g[4][3];
    load_lane_element(lane_F, lane_Dm_inv, F, g);
    // cof F, column by column: F₁ × F₂, F₂ × F₀, F₀ × F₁ (Fⱼ the columns of F).
    Vec G[3][3];
    for (int c = 0; c < 3; ++c) {
      const int i = (c + 1) % 3, j = (c + 2) % 3;
      G[0][c] = F[1][i] * F[2][j] - F[2][i] * F[1][j];
      G[1][c] = F[2][i] * F[0][j] - F[0][i] * F[2][j];
      G[2][c] = F[0][i] * F[1][j] - F[1][i] * F[0][j];
    }
    Vec Ic{}, J{};
    for (int r = 0; r < 3; ++r) {
      J += F[r][0] * G[r][0];
      for (int c = 0; c < 3; ++c)
        Ic += F[r][c] * F[r][c];
    }
    const Vec inverse = 1.0 / (Ic + 1.0);
    const Vec c1 = volume * k.mu * (1.0 - inverse);
    const Vec c2 = volume * (2.0 * k.mu) * inverse * inverse;
    const Vec c3 = volume * k.lambda;
    const Vec c4 = volume * k.lambda * (J - k.alpha);
    Vec Fg[4][3], Gg[4][3], c2Fg[4][3], c3Gg[4][3];
    for (int a = 0; a < 4; ++a)
      for (int r = 0; r < 3; ++r) {
        Fg[a][r] = F[r][0] * g[a][0] + F[r][1] * g[a][1] + F[r][2] * g[a][2];
        Gg[a][r] = G[r][0] * g[a][0] + G[r][1] * g[a][1] + G[r][2] * g[a][2];
        c2Fg[a][r] = c2 * Fg[a][r];
        c3Gg[a][r] = c3 * Gg[a][r];
      }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b <= a; ++b) {
        const Vec gg = c1 * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
        const Vec n[3] = {g[a][1] * g[b][2] - g[a][2] * g[b][1],
                          g[a][2] * g[b][0] - g[a][0] * g[b][2],
                          g[a][0] * g[b][1] - g[a][1] * g[b][0]};
        Vec v[3];
        for (int r = 0; r < 3; ++r)
          v[r] = c4 * (F[r][0] * n[0] + F[r][1] * n[1] + F[r][2] * n[2]);
        const Vec E[3][3] = {{Vec{}, v[2], -v[1]}, {-v[2], Vec{}, v[0]}, {v[1], -v[0], Vec{}}};
        for (int q = 0; q < 3; ++q)
          for (int r = 0; r < 3; ++r) {
            // Block (a, b), row q, column r: row 3a + q, column 3b + r.
            Vec value = c2Fg[a][q] * Fg[b][r] + c3Gg[a][q] * Gg[b][r] + E[q][r];
            if (q == r) value += gg;
            for (int l = 0; l < kLanes; ++l) {
              K[l][3 * b + r][3 * a + q] = value[l];
              if (a != b) K[l][3 * a + q][3 * b + r] = value[l];
            }
          }
      }
  }
};

/// Prefetches the sparse values that scatter_element_stiffness will update for the tet whose 48
/// offsets start at `offsets`.
inline void prefetch_block_entries(const int* offsets, const double* values) {
  for (int k = 0; k < 48; ++k)
    __builtin_prefetch(values + offsets[k], 1, 3);
}

/// Adds one tet's element stiffness (12 × 12, column-major) to the sparse values. `offsets` (48
/// per tet): for vertex pair (a, b) and column c, offsets[12b + 3a + c] is the position of
/// K(3a, 3b + c), with rows 3a + 1 and 3a + 2 following it.
inline void scatter_element_stiffness(const double (&K)[12][12], const int* offsets,
                                      double* values) {
  for (int b = 0; b < 4; ++b)
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) {
        double* entry = values + offsets[12 * b + 3 * a + c];
        const double* column = &K[3 * b + c][3 * a];
        entry[0] += column[0];
        entry[1] += column[1];
        entry[2] += column[2];
      }
}

}  // namespace strata::detail
