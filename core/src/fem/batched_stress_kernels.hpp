#pragma once
// Internal to elastic_model.cpp: force kernels that evaluate kLanes tets at once in
// structure-of-arrays form, so that the compiler vectorises across tets (AVX2: 4 doubles).
// Each kernel maps F (lane arrays) to P and, optionally, ψ — the same formulas as stvk.hpp and
// neohookean.hpp, checked against them in the tests.
#include <cmath>

#include "strata/core/fem/material.hpp"
#include "strata/core/fem/neohookean.hpp"

namespace strata::detail {

inline constexpr int kLanes = 4;
using Lanes = double[kLanes];

/// Explicit 4-wide vectors (GCC/Clang vector extension) for kernels the compiler would otherwise
/// vectorise only in part.
using Vec = double __attribute__((vector_size(kLanes * sizeof(double))));
inline Vec load_vec(const double* p) {
  Vec v;
  __builtin_memcpy(&v, p, sizeof(Vec));
  return v;
}
inline void store_vec(double* p, const Vec& v) {
  __builtin_memcpy(p, &v, sizeof(Vec));
}

/// F = Ds Dm⁻¹ of the kLanes tets `tets` (4 vertex indices each) at `positions` (3·#V).
/// lane_Dm_inv[(3c + j) · kLanes + l] = Dm⁻¹(j, c) of lane l.
[[gnu::always_inline]] inline void lane_deformation_gradient(const double* positions,
                                                             const int* tets,
                                                             const double* lane_Dm_inv,
                                                             double (&F)[3][3][kLanes]) {
  double x[4][3][kLanes];
  for (int l = 0; l < kLanes; ++l)
    for (int k = 0; k < 4; ++k)
      for (int r = 0; r < 3; ++r)
        x[k][r][l] = positions[3 * tets[4 * l + k] + r];
  double Ds[3][3][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < kLanes; ++l)
        Ds[r][j][l] = x[j + 1][r][l] - x[0][r][l];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < kLanes; ++l)
        F[r][c][l] = Ds[r][0][l] * lane_Dm_inv[(3 * c + 0) * kLanes + l] +
                     Ds[r][1][l] * lane_Dm_inv[(3 * c + 1) * kLanes + l] +
                     Ds[r][2][l] * lane_Dm_inv[(3 * c + 2) * kLanes + l];
}

/// StVK: E = ½(FᵀF − I), S = λ tr(E) I + 2μ E, P = F S, ψ = μ E:E + λ/2 tr(E)².
struct StvkLanes {
  double mu, lambda;
  explicit StvkLanes(const LameParameters& lame) : mu(lame.mu), lambda(lame.lambda) {}

  template <bool kWithEnergy>
  void operator()(const double (&lane_F)[3][3][kLanes], double (&P)[3][3][kLanes],
                  double (&psi)[kLanes]) const {
    Vec F[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        F[r][c] = load_vec(lane_F[r][c]);
    Vec E[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = a; b < 3; ++b) {
        E[a][b] = 0.5 * (F[0][a] * F[0][b] + F[1][a] * F[1][b] + F[2][a] * F[2][b]);
        if (a == b) E[a][b] -= 0.5;
        E[b][a] = E[a][b];
      }
    const Vec trace = E[0][0] + E[1][1] + E[2][2];
    Vec S[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        S[a][b] = (2.0 * mu) * E[a][b] + (a == b ? lambda * trace : Vec{});
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        store_vec(P[r][c], F[r][0] * S[0][c] + F[r][1] * S[1][c] + F[r][2] * S[2][c]);
    if constexpr (kWithEnergy) {
      Vec squared{};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          squared += E[a][b] * E[a][b];
      store_vec(psi, mu * squared + (0.5 * lambda) * trace * trace);
    }
  }
};

/// Stable neo-Hookean: P = μ'(1 − 1/(I_C + 1)) F + λ'(J − α) cof(F).
struct NeoHookeanLanes {
  NeoHookeanConstants k;
  double rest_energy;  ///< the constant that makes ψ(I) = 0, as in psi_neohookean
  explicit NeoHookeanLanes(const LameParameters& lame)
      : k(neohookean_constants(lame)),
        rest_energy(0.5 * k.lambda * (1.0 - k.alpha) * (1.0 - k.alpha) -
                    0.5 * k.mu * std::log(4.0)) {}

  template <bool kWithEnergy>
  void operator()(const double (&F)[3][3][kLanes], double (&P)[3][3][kLanes],
                  double (&psi)[kLanes]) const {
    double cof[3][3][kLanes];
    // Column c of cof(F) is the cross product of columns c+1 and c+2.
    for (int c = 0; c < 3; ++c) {
      const int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      for (int l = 0; l < kLanes; ++l) {
        cof[0][c][l] = F[1][c1][l] * F[2][c2][l] - F[2][c1][l] * F[1][c2][l];
        cof[1][c][l] = F[2][c1][l] * F[0][c2][l] - F[0][c1][l] * F[2][c2][l];
        cof[2][c][l] = F[0][c1][l] * F[1][c2][l] - F[1][c1][l] * F[0][c2][l];
      }
    }
    double Ic[kLanes], J[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      double sum = 0.0;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          sum += F[r][c][l] * F[r][c][l];
      Ic[l] = sum;
      J[l] = F[0][0][l] * cof[0][0][l] + F[1][0][l] * cof[1][0][l] + F[2][0][l] * cof[2][0][l];
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l)
          P[r][c][l] = k.mu * (1.0 - 1.0 / (Ic[l] + 1.0)) * F[r][c][l] +
                       k.lambda * (J[l] - k.alpha) * cof[r][c][l];
    if constexpr (kWithEnergy) {
      for (int l = 0; l < kLanes; ++l) {
        psi[l] = 0.5 * k.mu * (Ic[l] - 3.0) + 0.5 * k.lambda * (J[l] - k.alpha) * (J[l] - k.alpha) -
                 0.5 * k.mu * std::log(Ic[l] + 1.0) - rest_energy;
      }
    }
  }
};

}  // namespace strata::detail
