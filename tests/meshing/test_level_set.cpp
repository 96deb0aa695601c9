// Level sets: analytic distances of primitives, gradients, CSG, mesh-to-volume on closed and
// open surfaces, .vdb round trip and bad files.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "core/io_test_utils.hpp"
#include "meshing_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/level_set.hpp"

namespace strata {
namespace {

using testing::box_surface;
using testing::random_direction;
using testing::ScratchDir;

const Vector3d kCenter(0.1, 0.2, -0.05);
constexpr double kRadius = 0.5;
constexpr double kVoxel = 0.02;

/// Random points whose distance to the sphere is below `band` (all eight interpolation corners
/// then hold narrow-band values).
std::vector<Vector3d> points_near_sphere(int count, double band, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-band, band);
  std::vector<Vector3d> points;
  for (int i = 0; i < count; ++i)
    points.push_back(kCenter + (kRadius + offset(rng)) * random_direction(rng));
  return points;
}

TEST(LevelSet, SphereDistanceMatchesAnalyticWithinTheBand) {
  const LevelSetOptions options{kVoxel, 4.0};
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, options);
  EXPECT_DOUBLE_EQ(sphere.voxel_size(), kVoxel);
  EXPECT_NEAR(sphere.background(), 4.0 * kVoxel, 1e-7);
  // Corners lie within √3·h of the point: keep |d| ≤ background − √3·h.
  const double band = (4.0 - std::sqrt(3.0)) * kVoxel;
  // Trilinear interpolation error ≤ (h²/8)·Σ|∂²φ/∂x_i²| ≤ 3h²/(8ρ), ρ the smallest radius of
  // curvature of the distance's level sets near the point (≥ r − band).
  const double bound = 3.0 * kVoxel * kVoxel / (8.0 * (kRadius - band - std::sqrt(3.0) * kVoxel));
  double worst = 0.0;
  for (const Vector3d& p : points_near_sphere(500, band, 1)) {
    const double exact = (p - kCenter).norm() - kRadius;
    worst = std::max(worst, std::abs(sphere.signed_distance(p) - exact));
  }
  EXPECT_LT(worst, bound);
  EXPECT_LT(worst, 0.05 * kVoxel);
  // Outside the band: clamped to ±background.
  EXPECT_NEAR(sphere.signed_distance(kCenter), -sphere.background(), 1e-7);
  EXPECT_NEAR(sphere.signed_distance(kCenter + Vector3d(3, 0, 0)), sphere.background(), 1e-7);
}

TEST(LevelSet, GradientIsTheUnitNormalAndMatchesFiniteDifferences) {
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, {kVoxel, 4.0});
  const double band = (4.0 - std::sqrt(3.0)) * kVoxel;
  double worst_normal = 0.0;
  for (const Vector3d& p : points_near_sphere(500, band, 2)) {
    const Vector3d normal = (p - kCenter).normalized();
    Vector3d gradient;
    const double value = sphere.signed_distance_and_gradient(p, gradient);
    EXPECT_DOUBLE_EQ(value, sphere.signed_distance(p));
    EXPECT_EQ(gradient, sphere.gradient(p));
    worst_normal = std::max(worst_normal, (gradient - normal).norm());
    // The gradient is the interpolant's own: central differences inside one voxel agree.
    const double step = 1e-6 * kVoxel;
    for (int a = 0; a < 3; ++a) {
      const Vector3d e = step * Vector3d::Unit(a);
      const double fd =
          (sphere.signed_distance(p + e) - sphere.signed_distance(p - e)) / (2 * step);
      const bool near_face = std::abs(std::remainder(p(a) / kVoxel, 1.0)) < 1e-4;
      if (!near_face) {
        EXPECT_NEAR(gradient(a), fd, 1e-4);
      }
    }
  }
  // First-order accuracy of the interpolant's gradient: error ≲ √3·h/ρ.
  EXPECT_LT(worst_normal, std::sqrt(3.0) * kVoxel / (kRadius - 2 * kVoxel * 2.3));
}

TEST(LevelSet, SmoothGradientIsContinuousAcrossVoxelFaces) {
  // A band of 6 voxels: the 4³ stencil (up to 2√3·h from a point) stays on narrow-band values
  // for |d| ≤ (6 − 2√3)·h.
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, {kVoxel, 6.0});
  const double band = (6.0 - 2.0 * std::sqrt(3.0)) * kVoxel;
  const double step = 1e-7 * kVoxel;
  double worst_smooth_jump = 0.0, worst_trilinear_jump = 0.0, worst_fd = 0.0;
  double worst_value = 0.0, worst_normal = 0.0;
  int axis = 0;
  for (Vector3d p : points_near_sphere(300, band, 5)) {
    // On a voxel face (cell boundary of both interpolants) across axis a.
    const int a = axis++ % 3;
    p(a) = std::round(p(a) / kVoxel) * kVoxel;
    const Vector3d e = step * Vector3d::Unit(a);
    Vector3d below, above, at, trilinear_below, trilinear_above;
    const double value = sphere.smooth_signed_distance_and_gradient(p, at);
    sphere.smooth_signed_distance_and_gradient(p - e, below);
    sphere.smooth_signed_distance_and_gradient(p + e, above);
    sphere.signed_distance_and_gradient(p - e, trilinear_below);
    sphere.signed_distance_and_gradient(p + e, trilinear_above);
    worst_smooth_jump = std::max(worst_smooth_jump, (above - below).norm());
    worst_trilinear_jump =
        std::max(worst_trilinear_jump, (trilinear_above - trilinear_below).norm());
    // The gradient is the derivative of the value, also across the face.
    Vector3d dummy;
    const double fd = (sphere.smooth_signed_distance_and_gradient(p + e, dummy) -
                       sphere.smooth_signed_distance_and_gradient(p - e, dummy)) /
                      (2 * step);
    worst_fd = std::max(worst_fd, std::abs(fd - at(a)));
    worst_value = std::max(worst_value, std::abs(value - ((p - kCenter).norm() - kRadius)));
    worst_normal = std::max(worst_normal, (at - (p - kCenter).normalized()).norm());
  }
  // The trilinear gradient jumps at these faces (so the points do lie on them); the tricubic
  // one does not, beyond the change of a smooth field over 2·step.
  EXPECT_GT(worst_trilinear_jump, 1e-3);
  EXPECT_LT(worst_smooth_jump, 1e-5);
  // Central differences of float voxel values over 2e-7·h resolve the slope to about 1e-5.
  EXPECT_LT(worst_fd, 1e-4);
  // At least as accurate as the trilinear interpolant (its bound 3h²/(8ρ)), and its gradient
  // closer to the unit normal than the trilinear one's √3·h/ρ.
  const double rho = kRadius - band - 2.0 * std::sqrt(3.0) * kVoxel;
  EXPECT_LT(worst_value, 3.0 * kVoxel * kVoxel / (8.0 * rho));
  EXPECT_LT(worst_normal, std::sqrt(3.0) * kVoxel / rho);
}

TEST(LevelSet, SmoothSamplingReproducesALinearFieldAndTheVoxelValues) {
  const Vector3d normal = Vector3d(1.0, -2.0, 0.5).normalized();
  const Vector3d point(0.013, -0.021, 0.007);
  const auto plane = [&](const Vector3d& p) { return normal.dot(p - point); };
  const LevelSet level_set = level_set_from_function(
      plane, Vector3d(-0.3, -0.3, -0.3), Vector3d(0.3, 0.3, 0.3), {kVoxel, 6.0}, "plane");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-0.1, 0.1), offset(-2.0, 2.0);
  for (int i = 0; i < 200; ++i) {
    Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    p += (offset(rng) * kVoxel - plane(p)) * normal;  // within two voxels of the plane
    Vector3d gradient;
    const double value = level_set.smooth_signed_distance_and_gradient(p, gradient);
    // Float voxel values: exact to single precision.
    EXPECT_NEAR(value, plane(p), 1e-7);
    EXPECT_LT((gradient - normal).norm(), 1e-5);
    // At a voxel centre the interpolant is the voxel's value, as the trilinear one is.
    const Vector3d centre = (p / kVoxel).array().round().matrix() * kVoxel;
    EXPECT_NEAR(level_set.smooth_signed_distance_and_gradient(centre, gradient),
                level_set.signed_distance(centre), 1e-9);
  }
}

/// Catmull-Rom through samples at −1, 0, 1, 2, evaluated at t ∈ [0, 1) (Hermite form) and its
/// derivative in t.
double catmull_rom(const double f[4], double t, double& derivative) {
  const double a = 2.0 * f[1], b = f[2] - f[0], c = 2.0 * f[0] - 5.0 * f[1] + 4.0 * f[2] - f[3],
               d = -f[0] + 3.0 * f[1] - 3.0 * f[2] + f[3];
  derivative = 0.5 * (b + 2.0 * c * t + 3.0 * d * t * t);
  return 0.5 * (a + b * t + c * t * t + d * t * t * t);
}

/// The sampler's value and gradient at p against the tricubic Catmull-Rom of the 4³ voxel values
/// around p, read one by one at the voxel centres (where the trilinear sampler is the voxel's
/// value); returns the value.
double expect_tricubic_of_voxels(const LevelSet& level_set, const Vector3d& p) {
  const Vector3d index = p / kVoxel;
  const Vector3d base = index.array().floor().matrix();
  const Vector3d t = index - base;
  double voxels[4][4][4];
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 4; ++c)
        voxels[a][b][c] =
            level_set.signed_distance(kVoxel * (base + Vector3d(a - 1, b - 1, c - 1)));
  // Along z, then y, then x.
  double plane[4][4], plane_dz[4][4], line[4], line_dy[4], line_dz[4], unused;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      plane[a][b] = catmull_rom(voxels[a][b], t(2), plane_dz[a][b]);
  for (int a = 0; a < 4; ++a) {
    line[a] = catmull_rom(plane[a], t(1), line_dy[a]);
    line_dz[a] = catmull_rom(plane_dz[a], t(1), unused);
  }
  Vector3d expected_gradient;
  const double expected = catmull_rom(line, t(0), expected_gradient(0));
  expected_gradient(1) = catmull_rom(line_dy, t(0), unused);
  expected_gradient(2) = catmull_rom(line_dz, t(0), unused);
  expected_gradient /= kVoxel;
  Vector3d gradient;
  const double value = level_set.smooth_signed_distance_and_gradient(p, gradient);
  EXPECT_NEAR(value, expected, 1e-12) << "at " << p.transpose();
  EXPECT_LT((gradient - expected_gradient).norm(), 1e-9) << "at " << p.transpose();
  return value;
}

TEST(LevelSet, SmoothSamplingIsTheTricubicOfTheVoxelValuesEverywhere) {
  // Points inside the band, beyond it inside and outside the sphere, and far from it (where the
  // sampler answers the background without reading voxels).
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, {kVoxel, 4.0});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-kRadius - 12 * kVoxel, kRadius + 12 * kVoxel);
  int outside_band = 0;
  for (int i = 0; i < 400; ++i) {
    Vector3d p = kCenter + Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    if (i % 4 == 0) p = kCenter + (kRadius + 5.5 * kVoxel) * random_direction(rng);
    if (i % 4 == 1) p = kCenter + (kRadius + 0.9 * kVoxel) * random_direction(rng);
    expect_tricubic_of_voxels(sphere, p);
    outside_band += std::abs((p - kCenter).norm() - kRadius) > 4 * kVoxel;
  }
  EXPECT_GT(outside_band, 50);
  // Beyond the grid's leaves (8³ voxels each, around the band of 4), on a cube 20–40 voxels
  // out: the background itself, with a zero gradient.
  std::uniform_real_distribution<double> unit(-1.0, 1.0), scale(1.0, 2.0);
  for (int i = 0; i < 100; ++i) {
    Vector3d u(unit(rng), unit(rng), unit(rng));
    u /= u.lpNorm<Eigen::Infinity>();
    const Vector3d p = kCenter + scale(rng) * (kRadius + 20 * kVoxel) * u;
    Vector3d gradient;
    EXPECT_EQ(sphere.smooth_signed_distance_and_gradient(p, gradient), sphere.background());
    EXPECT_EQ(gradient, Vector3d::Zero());
  }
}

TEST(LevelSet, SmoothSamplingReadsTheInsideFarFromTheBand) {
  // The half-space z < 0 in a box: the grid holds leaves only near z = 0; deep below, its inside
  // is held by tiles of −background, far from every leaf. The sampler must read them there.
  const LevelSet half_space =
      level_set_from_function([](const Vector3d& p) { return p(2); }, Vector3d(-0.3, -0.3, -0.3),
                              Vector3d(0.3, 0.3, 0.3), {kVoxel, 4.0}, "half-space");
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> tangential(-0.25, 0.25), normal(-0.6, 0.6);
  int deep_inside = 0;
  for (int i = 0; i < 300; ++i) {
    const Vector3d p(tangential(rng), tangential(rng), normal(rng));
    const double value = expect_tricubic_of_voxels(half_space, p);
    deep_inside += p(2) < -0.2 && std::abs(value + half_space.background()) < 1e-12;
  }
  EXPECT_GT(deep_inside, 20);
}

TEST(LevelSet, SmoothSamplingFarAwayIsTheBackgroundAndOfANonFinitePointNotANumber) {
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, {kVoxel, 4.0});
  Vector3d gradient;
  // Far beyond any voxel index an int can hold.
  EXPECT_EQ(sphere.smooth_signed_distance_and_gradient(Vector3d(1e300, 0.0, -1e300), gradient),
            sphere.background());
  EXPECT_EQ(gradient, Vector3d::Zero());
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    EXPECT_TRUE(
        std::isnan(sphere.smooth_signed_distance_and_gradient(Vector3d(0.0, bad, 0.0), gradient)));
    EXPECT_TRUE(gradient.array().isNaN().all());
  }
}

TEST(LevelSet, CsgOfTwoSpheres) {
  const LevelSetOptions options{kVoxel, 3.0};
  const Vector3d ca(0, 0, 0), cb(0.6, 0, 0);
  const LevelSet a = level_set_sphere(ca, 0.5, options);
  const LevelSet b = level_set_sphere(cb, 0.5, options);
  const LevelSet united = csg_union(a, b);
  const LevelSet common = csg_intersection(a, b);
  const LevelSet a_minus_b = csg_difference(a, b);
  const Vector3d in_both(0.3, 0, 0), in_a(-0.3, 0, 0), in_b(0.9, 0, 0), in_neither(0.3, 0.45, 0);
  EXPECT_LT(united.signed_distance(in_both), 0);
  EXPECT_LT(united.signed_distance(in_a), 0);
  EXPECT_LT(united.signed_distance(in_b), 0);
  EXPECT_GT(united.signed_distance(in_neither), 0);
  EXPECT_LT(common.signed_distance(in_both), 0);
  EXPECT_GT(common.signed_distance(in_a), 0);
  EXPECT_GT(common.signed_distance(in_b), 0);
  EXPECT_LT(a_minus_b.signed_distance(in_a), 0);
  EXPECT_GT(a_minus_b.signed_distance(in_both), 0);
  EXPECT_GT(a_minus_b.signed_distance(in_b), 0);
  // At voxel centres (no interpolation) the values are min / max of the operands' voxel values
  // wherever both lie in their bands.
  int checked = 0;
  for (int i = -30; i <= 60; ++i) {
    for (int j = -30; j <= 30; ++j) {
      const Vector3d p = kVoxel * Vector3d(i, j, 3);
      const double da = (p - ca).norm() - 0.5, db = (p - cb).norm() - 0.5;
      if (std::abs(da) > 2 * kVoxel || std::abs(db) > 2 * kVoxel) continue;
      ++checked;
      const double fa = a.signed_distance(p), fb = b.signed_distance(p);
      EXPECT_NEAR(fa, da, 1e-3 * kVoxel);
      EXPECT_EQ(united.signed_distance(p), std::min(fa, fb));
      EXPECT_EQ(common.signed_distance(p), std::max(fa, fb));
      EXPECT_EQ(a_minus_b.signed_distance(p), std::max(fa, -fb));
    }
  }
  EXPECT_GT(checked, 20);
  // Inputs are unchanged.
  EXPECT_LT(b.signed_distance(in_b), 0);
  EXPECT_THROW(csg_union(a, level_set_sphere(cb, 0.5, {0.03, 3.0})), InputError);
}

TEST(LevelSet, PrimitivesMatchTheirDistanceFunctions) {
  const LevelSetOptions options{0.01, 3.0};
  const LevelSet box = level_set_box(Vector3d(0, 0, 0), Vector3d(1, 0.5, 0.4), options);
  // Near face centres the box distance is linear: interpolation is exact up to float rounding.
  EXPECT_NEAR(box.signed_distance(Vector3d(0.5, 0.25, 0.413)), 0.013, 1e-6);
  EXPECT_NEAR(box.signed_distance(Vector3d(1.004, 0.25, 0.2)), 0.004, 1e-6);
  EXPECT_NEAR(box.signed_distance(Vector3d(0.5, 0.012, 0.2)), -0.012, 1e-6);
  const LevelSet capsule = level_set_capsule(Vector3d(0, 0, 0), Vector3d(1, 0, 0), 0.2, options);
  EXPECT_NEAR(capsule.signed_distance(Vector3d(0.5, 0.215, 0)), 0.015, 0.03 * 0.01);
  EXPECT_NEAR(capsule.signed_distance(Vector3d(-0.21, 0, 0)), 0.01, 0.03 * 0.01);
  EXPECT_NEAR(capsule.signed_distance(Vector3d(0.5, 0, 0)), -capsule.background(), 1e-7);
  const LevelSet torus = level_set_torus(Vector3d(0, 0, 0), Vector3d(0, 0, 1), 0.5, 0.1, options);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0.61, 0, 0)), 0.01, 0.03 * 0.01);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0, 0.5, 0.085)), -0.015, 0.03 * 0.01);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0, 0, 0)), torus.background(), 1e-7);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0.5, 0, 0)), -torus.background(), 1e-7);
}

TEST(LevelSet, ToSurfaceEnclosesTheSphereVolume) {
  const LevelSet sphere = level_set_sphere(kCenter, kRadius, {kVoxel, 3.0});
  const SurfaceMesh surface = sphere.to_surface();
  ASSERT_GT(surface.triangles.rows(), 100);
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  EXPECT_NEAR(enclosed_volume(surface), exact, 0.01 * exact);  // positive: oriented outward
  for (Index v = 0; v < surface.vertices.rows(); ++v)
    EXPECT_NEAR((surface.vertices.row(v).transpose() - kCenter).norm(), kRadius, 0.05 * kVoxel);
}

TEST(LevelSet, ClosedBoxSurfaceGivesExactDistancesNearFaces) {
  const SurfaceLevelSet result =
      surface_to_level_set(box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1)), {0.05, 3.0});
  EXPECT_TRUE(result.topology.watertight()) << result.topology.summary();
  EXPECT_EQ(result.topology.edges, 18);
  const LevelSet& phi = result.level_set;
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.5, 0.5, 0.04)), -0.04, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.5, 0.43, 1.07)), 0.07, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.97, 0.5, 0.6)), -0.03, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.5, 0.5, 0.5)), -phi.background(), 1e-7);
  EXPECT_NEAR(phi.signed_distance(Vector3d(3, 0.5, 0.5)), phi.background(), 1e-7);
  const auto [lo, hi] = phi.bounding_box();
  EXPECT_NEAR(lo(0), -0.1, 0.051);
  EXPECT_NEAR(hi(2), 1.1, 0.051);
}

TEST(LevelSet, OpenBoxIsReportedAndStillUsable) {
  SurfaceMesh open = box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  open.triangles.conservativeResize(10, 3);  // drop the +z face
  const SurfaceLevelSet result = surface_to_level_set(open, {0.05, 3.0});
  EXPECT_FALSE(result.topology.watertight());
  EXPECT_EQ(result.topology.boundary_edges, 4);
  EXPECT_NE(result.topology.summary().find("not watertight: 4 boundary edges"), std::string::npos);
  const LevelSet& phi = result.level_set;
  EXPECT_LT(phi.signed_distance(Vector3d(0.5, 0.5, 0.5)), 0.0);
  EXPECT_LT(phi.signed_distance(Vector3d(0.3, 0.6, 0.8)), 0.0);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.5, 0.5, 0.04)), -0.04, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.5, 0.5, -0.07)), 0.07, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(1.06, 0.5, 0.5)), 0.06, 1e-6);
  EXPECT_NEAR(phi.signed_distance(Vector3d(0.96, 0.5, 0.5)), -0.04, 1e-6);
  EXPECT_GT(phi.signed_distance(Vector3d(0.5, 0.5, 1.5)), 0.0);
  EXPECT_GT(phi.signed_distance(Vector3d(3, 3, 3)), 0.0);
  // Misoriented triangles (one face flipped) are reported, and the distances stay right.
  SurfaceMesh flipped = box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  flipped.triangles.row(0) = flipped.triangles.row(0).reverse().eval();
  const SurfaceLevelSet misoriented = surface_to_level_set(flipped, {0.05, 3.0});
  EXPECT_EQ(misoriented.topology.misoriented_edges, 3);
  EXPECT_LT(misoriented.level_set.signed_distance(Vector3d(0.5, 0.5, 0.5)), 0.0);
  EXPECT_NEAR(misoriented.level_set.signed_distance(Vector3d(0.5, 0.5, 1.04)), 0.04, 1e-6);
}

TEST(LevelSet, VdbRoundTrip) {
  ScratchDir dir("level_set_vdb");
  const LevelSet torus =
      level_set_torus(Vector3d(0.1, 0, 0), Vector3d(1, 1, 0), 0.4, 0.1, {0.02, 3.0});
  torus.write_vdb(dir / "torus.vdb");
  const LevelSet read = LevelSet::read_vdb(dir / "torus.vdb");
  const LevelSet by_name = LevelSet::read_vdb(dir / "torus.vdb", "torus");
  EXPECT_EQ(read.name(), "torus");
  EXPECT_EQ(read.voxel_size(), torus.voxel_size());
  EXPECT_EQ(read.background(), torus.background());
  EXPECT_EQ(read.num_active_voxels(), torus.num_active_voxels());
  std::mt19937 rng(4);
  for (int i = 0; i < 200; ++i) {
    const Vector3d p =
        testing::random_point(rng, Vector3d(-0.6, -0.6, -0.6), Vector3d(0.7, 0.6, 0.6));
    EXPECT_EQ(read.signed_distance(p), torus.signed_distance(p));
    EXPECT_EQ(by_name.signed_distance(p), torus.signed_distance(p));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "torus.vdb.tmp"));
}

TEST(LevelSet, MissingOrCorruptVdbNamesTheFile) {
  ScratchDir dir("level_set_bad_vdb");
  const auto expect_error = [](const std::filesystem::path& path, const std::string& grid) {
    try {
      LevelSet::read_vdb(path, grid);
      ADD_FAILURE() << "no error for " << path;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
    }
  };
  expect_error(dir / "missing.vdb", "");
  testing::write_text(dir / "corrupt.vdb", "this is not a vdb file\n");
  expect_error(dir / "corrupt.vdb", "");
  level_set_sphere(kCenter, kRadius, {0.05, 3.0}).write_vdb(dir / "sphere.vdb");
  expect_error(dir / "sphere.vdb", "no_such_grid");
  // A truncated file.
  const std::string content = testing::read_text(dir / "sphere.vdb");
  testing::write_text(dir / "truncated.vdb", content.substr(0, content.size() / 2));
  expect_error(dir / "truncated.vdb", "");
}

TEST(LevelSet, BadInputIsRejected) {
  EXPECT_THROW(level_set_sphere(kCenter, -1.0, {0.05, 3.0}), InputError);
  EXPECT_THROW(level_set_sphere(kCenter, 1.0, {0.0, 3.0}), InputError);
  EXPECT_THROW(level_set_sphere(kCenter, 1.0, {0.05, 0.5}), InputError);
  EXPECT_THROW(surface_to_level_set(SurfaceMesh{}, {0.05, 3.0}), InputError);
  SurfaceMesh bad = box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  bad.triangles(3, 1) = 99;
  EXPECT_THROW(surface_to_level_set(bad, {0.05, 3.0}), InputError);
  // A band too fine for its surface (about 10¹¹ voxels) is refused before any allocation, naming
  // the voxel size; one a thousand times coarser is built.
  for (const auto& build : std::vector<std::function<void(double)>>{
           [](double h) {
             level_set_sphere(kCenter, 1.0, {h, 3.0});
           },
           [](double h) {
             surface_to_level_set(box_surface(Vector3d(0, 0, 0), Vector3d(2, 2, 2)), {h, 3.0});
           }}) {
    try {
      build(2e-5);
      ADD_FAILURE() << "a band of about 1e11 voxels was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("voxel size 2e-05 m would need about"),
                std::string::npos)
          << error.what();
    }
    EXPECT_NO_THROW(build(2e-2));
  }
}

}  // namespace
}  // namespace strata
