#include "strata/core/fem/polar_decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace strata {

namespace {

/// Pairs whose columns satisfy |b_p · b_q| ≤ kOrthogonality ‖b_p‖ ‖b_q‖ count as orthogonal.
constexpr double kOrthogonality = 1e-15;
constexpr int kMaxSweeps = 12;

/// One Jacobi rotation of columns p, q of B (and of V) making them orthogonal. Returns |sin θ| of
/// the rotation angle, 0 when the pair already is orthogonal (then nothing changes).
inline double orthogonalize_pair(Matrix3d& B, Matrix3d& V, int p, int q) {
  const double alpha = B.col(p).squaredNorm();
  const double beta = B.col(q).squaredNorm();
  const double gamma = B.col(p).dot(B.col(q));
  if (std::abs(gamma) <= kOrthogonality * std::sqrt(alpha * beta)) return 0.0;
  // cot 2θ = (β − α) / 2γ = d / g; θ is the smaller of the two angles. With h = √(d² + g²) and
  // k = |d| + h: tan θ = sign(d) g / k, and 1 + tan²θ = 2h / k, so c = k / √(2hk).
  const double d = beta - alpha, g = 2.0 * gamma;
  const double h_squared = d * d + g * g;
  double c, s;
  if (std::abs(g) < 1e-4 * std::abs(d)) {
    // Small angle (most rotations after the first sweep): with r = g / d, tan θ = r / (1 + √(1 +
    // r²)) = r (1/2 − r²/8) + O(r⁵) and c = 1 − t²/2 + O(t⁴); both errors ≤ 1e-17 relative.
    const double r = g / d;
    const double t = r * (0.5 - 0.125 * r * r);
    c = 1.0 - 0.5 * t * t;
    s = c * t;
  } else if (h_squared > 1e-300) {
    const double h = std::sqrt(h_squared);
    const double k = std::abs(d) + h;
    const double inverse_root = 1.0 / std::sqrt(2.0 * h * k);
    c = k * inverse_root;
    s = (d < 0.0 ? -g : g) * inverse_root;
  } else {  // tiny columns: the same angle from ζ = d / g, safe against underflow
    const double zeta = d / g;
    const double t = std::abs(zeta) > 1e150 ? 0.5 / zeta
                                            : std::copysign(1.0, zeta) /
                                                  (std::abs(zeta) + std::sqrt(1.0 + zeta * zeta));
    c = 1.0 / std::sqrt(1.0 + t * t);
    s = c * t;
  }
  for (int r = 0; r < 3; ++r) {
    const double bp = B(r, p), bq = B(r, q);
    B(r, p) = c * bp - s * bq;
    B(r, q) = s * bp + c * bq;
    const double vp = V(r, p), vq = V(r, q);
    V(r, p) = c * vp - s * vq;
    V(r, q) = s * vp + c * vq;
  }
  return std::abs(s);
}

/// A unit vector orthogonal to the unit vector u.
inline Vector3d any_orthogonal_unit(const Vector3d& u) {
  Index axis = 0;
  u.cwiseAbs().minCoeff(&axis);
  return u.cross(Vector3d::Unit(axis)).normalized();
}

inline void swap_columns(Matrix3d& B, Matrix3d& V, Vector3d& squared_norms, int i, int j) {
  B.col(i).swap(B.col(j));
  V.col(i).swap(V.col(j));
  std::swap(squared_norms[i], squared_norms[j]);
}

}  // namespace

RotationVariantSvd rotation_variant_svd(const Matrix3d& F) {
  // Power-of-two prescaling keeps squared norms finite; exact, so typical inputs are untouched.
  const double largest = F.cwiseAbs().maxCoeff();
  int exponent = 0;
  if (!(largest >= 1e-100 && largest <= 1e100)) {
    if (largest == 0.0) return {Matrix3d::Identity(), Vector3d::Zero(), Matrix3d::Identity()};
    if (!std::isfinite(largest)) {  // NaN / inf propagate instead of passing for a rest state
      const double nan = std::numeric_limits<double>::quiet_NaN();
      return {Matrix3d::Constant(nan), Vector3d::Constant(nan), Matrix3d::Constant(nan)};
    }
    std::frexp(largest, &exponent);
  }
  Matrix3d B = exponent == 0 ? F : Matrix3d(std::ldexp(1.0, -exponent) * F);
  Matrix3d V = Matrix3d::Identity();
  // A rotation by θ disturbs the other pairs' orthogonality by O(θ · their residual), so after a
  // sweep whose rotations all had |sin θ| ≤ 1e-8 every pair is orthogonal to ~1e-16.
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    const double sin01 = orthogonalize_pair(B, V, 0, 1);
    const double sin02 = orthogonalize_pair(B, V, 0, 2);
    const double sin12 = orthogonalize_pair(B, V, 1, 2);
    if (std::max({sin01, sin02, sin12}) <= 1e-8) break;
  }

  // Sort columns by length, descending; every swap flips det V.
  Vector3d squared_norms = B.colwise().squaredNorm().transpose();
  bool reflected = false;
  if (squared_norms[0] < squared_norms[1]) {
    swap_columns(B, V, squared_norms, 0, 1);
    reflected = !reflected;
  }
  if (squared_norms[1] < squared_norms[2]) {
    swap_columns(B, V, squared_norms, 1, 2);
    reflected = !reflected;
  }
  if (squared_norms[0] < squared_norms[1]) {
    swap_columns(B, V, squared_norms, 0, 1);
    reflected = !reflected;
  }
  if (reflected) {
    V.col(2) = -V.col(2);
    B.col(2) = -B.col(2);
  }

  RotationVariantSvd svd;
  svd.V = V;
  if (squared_norms[0] == 0.0) {
    svd.U.setIdentity();
    svd.sigma.setZero();
    return svd;
  }
  const Vector3d u0 = B.col(0) / std::sqrt(squared_norms[0]);
  const Vector3d b1 = B.col(1) - u0.dot(B.col(1)) * u0;
  const double b1_norm = b1.norm();
  const Vector3d u1 = b1_norm > 0.0 ? Vector3d(b1 / b1_norm) : any_orthogonal_unit(u0);
  svd.U.col(0) = u0;
  svd.U.col(1) = u1;
  svd.U.col(2) = u0.cross(u1);
  const double scale = std::ldexp(1.0, exponent);
  svd.sigma[0] = scale * std::sqrt(squared_norms[0]);
  svd.sigma[1] = scale * std::sqrt(squared_norms[1]);
  svd.sigma[2] = std::copysign(scale * std::sqrt(squared_norms[2]), svd.U.col(2).dot(B.col(2)));
  return svd;
}

namespace {

/// Fast path for det F > 0: scaled Newton iteration X ← (γX + X⁻ᵀ/γ)/2, X₀ = F (Higham 1986,
/// "Computing the polar decomposition — with applications"). Returns false, leaving R untouched,
/// for inverted, nearly singular or extremely scaled F, and when it does not converge.
bool newton_polar_rotation(const Matrix3d& F, Matrix3d& R) {
  // Nearly flat F (det F < kMinVolumeRatio · (‖F‖²_F / 3)^{3/2}) goes to the SVD instead.
  constexpr double kMinVolumeRatio = 1e-6;
  constexpr int kMaxIterations = 12;
  const double mean_square = F.squaredNorm() / 3.0;
  if (!(mean_square >= 1e-150 && mean_square <= 1e150)) return false;
  Matrix3d X = F;
  double change = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Matrix3d cofactor;
    cofactor.col(0) = X.col(1).cross(X.col(2));
    cofactor.col(1) = X.col(2).cross(X.col(0));
    cofactor.col(2) = X.col(0).cross(X.col(1));
    const double det = X.col(0).dot(cofactor.col(0));
    if (iteration == 0 && !(det >= kMinVolumeRatio * mean_square * std::sqrt(mean_square)))
      return false;
    const Matrix3d inverse_transpose = (1.0 / det) * cofactor;
    // Frobenius scaling γ = (‖X⁻¹‖/‖X‖)^{1/2} while X is far from orthogonal in size or shape
    // (γ⁴ outside [¼, 4]); checked only at the start and after large steps, since near
    // convergence unscaled steps keep the quadratic rate.
    double gamma = 1.0;
    if (change > 1e-2) {
      const double inverse_norm = inverse_transpose.squaredNorm(), norm = X.squaredNorm();
      if (!(inverse_norm > 0.25 * norm && inverse_norm < 4.0 * norm))
        gamma = std::sqrt(std::sqrt(inverse_norm / norm));
    }
    const Matrix3d next = (0.5 * gamma) * X + (0.5 / gamma) * inverse_transpose;
    change = (next - X).squaredNorm();
    X = next;
    // Quadratic convergence: the error after a step of size ‖ΔX‖ ≤ 1e-7 is about ‖ΔX‖²/2 ≤ 5e-15.
    if (change <= 1e-14) {
      R = X;
      return true;
    }
  }
  return false;
}

}  // namespace

Matrix3d polar_rotation(const Matrix3d& F) {
  Matrix3d R;
  if (newton_polar_rotation(F, R)) return R;
  const RotationVariantSvd svd = rotation_variant_svd(F);
  return svd.U * svd.V.transpose();
}

}  // namespace strata
