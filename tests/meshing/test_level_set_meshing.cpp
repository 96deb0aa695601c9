// Level sets and implicit CSG shapes through Mesh_3 (mesh_level_set, mesh_implicit_shape,
// mesh_level_set_file): volumes against closed forms, .vdb files against the primitives they came
// from, cache reuse, and refused input.
//
// Tolerances: every boundary vertex lies on the zero set, so the mesh's boundary is a polyhedron
// inscribed in the smooth surface with facets within `facet_distance` δ of it (Mesh_3's criterion);
// on a sphere of radius r such a facet cuts off at most δ of the radius, so the volume deficit is
// below A·δ = 3δ/r · V. The level set's trilinear interpolation moves the zero set by about
// (voxel)²/(8r), far below δ here. Creases (a union's seam, a box's edges, which the implicit
// domain does not protect) are rounded by the trilinear interpolation of the kinked distance over
// about a voxel h and chopped by facets within about δ: a wedge of cross-section below h² + δ² per
// unit length. Measured over facet sizes 0.1–0.5 (sphere) and 0.1–0.4 (box minus sphere, radii
// 0.3–0.9), δ 0.005–0.04: the sphere's
// error reached 0.95 of its bound, the box minus sphere's 0.6.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/meshing/implicit_shape.hpp"
#include "strata/meshing/level_set.hpp"
#include "strata/meshing/mesh_level_set.hpp"

namespace strata {
namespace {

constexpr double kPi = 3.14159265358979323846;

double ball_volume(double r) {
  return 4.0 / 3.0 * kPi * r * r * r;
}

/// Coarse and fast: no optimisation (it does not move boundary vertices off the surface).
MeshingOptions coarse_options(double cell_size, double facet_distance) {
  MeshingOptions options;
  options.cell_size = cell_size;
  options.facet_distance = facet_distance;
  options.perturb = false;
  options.exude = false;
  return options;
}

std::string error_of(const std::function<void()>& run) {
  try {
    run();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

/// A fresh folder per test.
class TempFolder {
 public:
  TempFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_path = std::filesystem::temp_directory_path() /
             ("strata_meshing_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~TempFolder() { std::filesystem::remove_all(m_path); }
  const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

TEST(LevelSetMeshing, SphereVolumeWithinTheFacetDistanceBound) {
  const double r = 1.0, delta = 0.02;
  const MeshingOptions options = coarse_options(0.3, delta);
  const LevelSetMeshingResult result =
      mesh_implicit_shape(ImplicitShape::sphere(Vector3d(0.5, -0.2, 0.1), r), 0.0, options);
  ASSERT_GT(result.mesh.tets.rows(), 0);
  EXPECT_NO_THROW(validate_tet_mesh(result.mesh, "sphere"));
  const double exact = ball_volume(r);
  const double volume = mesh_volume(result.mesh);
  EXPECT_LT(volume, exact * (1.0 + 1e-3));
  EXPECT_NEAR(volume, exact, 3.0 * delta / r * exact);
  // Boundary vertices on the sphere, to the level set's interpolation error.
  const MatrixX3i faces = boundary_faces(result.mesh.tets);
  for (Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(
          (result.mesh.vertices.row(faces(f, k)).transpose() - Vector3d(0.5, -0.2, 0.1)).norm(), r,
          2e-3);
  EXPECT_EQ(result.report.route, kLevelSetRoute);
  EXPECT_FALSE(result.report.from_cache);
  EXPECT_EQ(result.report.quality.tets, result.mesh.tets.rows());
  // The reference volume (zero iso-surface at voxel resolution) is close to the ball too.
  EXPECT_NEAR(result.report.surface_volume, exact, 0.01 * exact);
}

TEST(LevelSetMeshing, DefaultVoxelSizeIsAQuarterOfTheFacetSize) {
  MeshingOptions options = coarse_options(0.4, 0.0);
  EXPECT_DOUBLE_EQ(implicit_voxel_size(options), 0.1);
  options.facet_size = 0.2;
  EXPECT_DOUBLE_EQ(implicit_voxel_size(options), 0.05);
}

TEST(LevelSetMeshing, UnionOfOverlappingSpheres) {
  const double r = 0.5, d = 0.6, delta = 0.01, facet = 0.15;
  MeshingOptions options = coarse_options(facet, delta);
  const ImplicitShape shape = ImplicitShape::csg(
      ImplicitShape::Kind::union_of,
      {ImplicitShape::sphere(Vector3d(0, 0, 0), r), ImplicitShape::sphere(Vector3d(d, 0, 0), r)});
  const LevelSetMeshingResult result = mesh_implicit_shape(shape, 0.0, options);
  // Union = two balls minus their lens: V_lens = π (4r + d)(2r − d)² / 12.
  const double lens = kPi * (4.0 * r + d) * (2.0 * r - d) * (2.0 * r - d) / 12.0;
  const double exact = 2.0 * ball_volume(r) - lens;
  // Area of the union (two spheres less their caps of height r − d/2 each) · δ, plus the seam
  // circle (radius √(r² − d²/4)) · (h² + δ²).
  const double cap = 2.0 * kPi * r * (r - d / 2.0);
  const double area = 2.0 * (4.0 * kPi * r * r - cap);
  const double seam = 2.0 * kPi * std::sqrt(r * r - d * d / 4.0);
  const double h = implicit_voxel_size(options);
  EXPECT_NEAR(mesh_volume(result.mesh), exact, area * delta + seam * (h * h + delta * delta));
  // Sharper than the bound: the union is far from either ball and from their sum.
  EXPECT_GT(mesh_volume(result.mesh), ball_volume(r) * 1.2);
  EXPECT_LT(mesh_volume(result.mesh), 2.0 * ball_volume(r) - 0.5 * lens);
}

TEST(LevelSetMeshing, BoxMinusSphere) {
  // The unit box minus a sphere centred on its corner (1, 1, 1): only an octant of the ball is
  // inside the box, V = 1 − V_ball / 8.
  const double r = 0.6, delta = 0.01, facet = 0.15, h = 0.02;
  MeshingOptions options = coarse_options(facet, delta);
  const ImplicitShape shape = ImplicitShape::csg(
      ImplicitShape::Kind::difference, {ImplicitShape::box(Vector3d(0, 0, 0), Vector3d(1, 1, 1)),
                                        ImplicitShape::sphere(Vector3d(1, 1, 1), r)});
  const LevelSetMeshingResult result = mesh_implicit_shape(shape, h, options);
  const double exact = 1.0 - ball_volume(r) / 8.0;
  // Flat faces are meshed exactly (vertices on a plane); the spherical octant (area π r² / 2)
  // contributes δ per unit area; creases: the 12 box edges less the cut (12 − 3r) and the 3
  // quarter circles of the cut (3 π r / 2).
  const double creases = 12.0 - 3.0 * r + 3.0 * kPi * r / 2.0;
  const double tolerance = kPi * r * r / 2.0 * delta + creases * (h * h + delta * delta);
  EXPECT_NEAR(mesh_volume(result.mesh), exact, tolerance);
  EXPECT_LT(tolerance, 0.2 * ball_volume(r) / 8.0);  // the octant is resolved
}

TEST(LevelSetMeshing, VdbFileMeshesLikeThePrimitiveAndIsCached) {
  TempFolder folder;
  const MeshingOptions options = coarse_options(0.4, 0.04);
  const ImplicitShape sphere = ImplicitShape::sphere(Vector3d(0, 0, 0), 1.0);
  LevelSetOptions level_set_options;
  level_set_options.voxel_size = implicit_voxel_size(options);
  const std::filesystem::path file = folder.path() / "ball.vdb";
  implicit_shape_level_set(sphere, level_set_options).write_vdb(file);

  const LevelSetMeshingResult primitive = mesh_implicit_shape(sphere, 0.0, options);
  const MeshCache cache(folder.path() / "cache");
  const LevelSetMeshingResult first = mesh_level_set_file(file, "", options, &cache);
  EXPECT_FALSE(first.report.from_cache);
  EXPECT_TRUE(std::filesystem::exists(cache.entry_path(first.cache_key)));
  // Same float grid, same box, same seed: the same mesh.
  EXPECT_EQ(first.mesh.tets, primitive.mesh.tets);
  EXPECT_EQ(first.mesh.vertices, primitive.mesh.vertices);

  const LevelSetMeshingResult second = mesh_level_set_file(file, "", options, &cache);
  EXPECT_TRUE(second.report.from_cache);
  EXPECT_EQ(second.cache_key, first.cache_key);
  EXPECT_EQ(second.mesh.tets, first.mesh.tets);
  EXPECT_EQ(second.mesh.vertices, first.mesh.vertices);
  EXPECT_DOUBLE_EQ(second.report.surface_volume, first.report.surface_volume);

  // The grid name, the options and the shape are part of the key.
  EXPECT_NE(mesh_level_set_file(file, "sphere", options, nullptr).cache_key, first.cache_key);
  MeshingOptions other = options;
  other.seed = 1;
  EXPECT_NE(mesh_level_set_file(file, "", other, nullptr).cache_key, first.cache_key);
  EXPECT_NE(
      mesh_implicit_shape(ImplicitShape::sphere(Vector3d(0, 0, 0), 0.9), 0.0, options).cache_key,
      primitive.cache_key);
}

TEST(LevelSetMeshing, DescriptionIsCanonical) {
  const ImplicitShape shape =
      ImplicitShape::csg(ImplicitShape::Kind::intersection,
                         {ImplicitShape::capsule(Vector3d(0, 0, 0), Vector3d(1, 0, 0), 0.25),
                          ImplicitShape::torus(Vector3d(0, 0, 0), Vector3d(0, 0, 1), 1.0, 0.1)});
  EXPECT_EQ(
      describe_implicit_shape(shape),
      "intersection(capsule([0,0,0],[1,0,0],0.25),torus([0,0,0],[0,0,1],1,0.10000000000000001))");
}

TEST(LevelSetMeshing, TorusAroundItsAxis) {
  // Torus around x: volume 2π² R r²; its level set spans ±(R + r) in y and z, ±r in x.
  const double R = 0.6, r = 0.2;
  LevelSetOptions level_set_options;
  level_set_options.voxel_size = 0.025;
  const LevelSet torus = implicit_shape_level_set(
      ImplicitShape::torus(Vector3d(0, 0, 0), Vector3d(2, 0, 0), R, r), level_set_options);
  // φ clamps to ∓background (3 voxels) away from the surface.
  EXPECT_NEAR(torus.signed_distance(Vector3d(0, R, 0)), -torus.background(), 1e-6);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0, 0, R + r)), 0.0, 1e-3);
  EXPECT_NEAR(torus.signed_distance(Vector3d(0, 0, R - r - 0.05)), 0.05, 1e-3);
  EXPECT_NEAR(torus.signed_distance(Vector3d(R, 0, 0)), torus.background(), 1e-6);
  EXPECT_NEAR(level_set_volume(torus), 2.0 * kPi * kPi * R * r * r,
              0.02 * 2 * kPi * kPi * R * r * r);
}

TEST(LevelSetMeshing, RefusedInput) {
  TempFolder folder;
  const MeshingOptions options = coarse_options(0.4, 0.0);
  EXPECT_NE(error_of([&] {
              mesh_level_set_file(folder.path() / "missing.vdb", "", options);
            }).find("missing.vdb': no such file"),
            std::string::npos);
  const std::filesystem::path file = folder.path() / "ball.vdb";
  LevelSetOptions level_set_options;
  level_set_options.voxel_size = 0.1;
  level_set_sphere(Vector3d(0, 0, 0), 1.0, level_set_options).write_vdb(file);
  EXPECT_NE(error_of([&] {
              mesh_level_set_file(file, "nothere", options);
            }).find("no grid named 'nothere'"),
            std::string::npos);
  EXPECT_EQ(error_of([&] {
              mesh_implicit_shape(ImplicitShape::csg(ImplicitShape::Kind::union_of, {}), 0.0,
                                  options);
            }),
            "implicit union: needs at least 1 operand");
  EXPECT_EQ(error_of([&] {
              mesh_implicit_shape(ImplicitShape::csg(ImplicitShape::Kind::difference,
                                                     {ImplicitShape::sphere(Vector3d::Zero(), 1)}),
                                  0.0, options);
            }),
            "implicit difference: needs exactly 2 operands, got 1");
  EXPECT_NE(error_of([&] {
              mesh_implicit_shape(ImplicitShape::sphere(Vector3d::Zero(), -1), 0.0, options);
            }).find("radius must be a positive number"),
            std::string::npos);
  // Disjoint operands: an empty intersection.
  EXPECT_EQ(error_of([&] {
              mesh_implicit_shape(
                  ImplicitShape::csg(ImplicitShape::Kind::intersection,
                                     {ImplicitShape::sphere(Vector3d(0, 0, 0), 0.5),
                                      ImplicitShape::sphere(Vector3d(3, 0, 0), 0.5)}),
                  0.0, options);
            }).find("encloses no volume") != std::string::npos,
            true);
  // An inverted grid (negative outside) bounds no solid.
  const LevelSet inverted = level_set_from_function(
      [](const Vector3d& p) { return 1.0 - p.norm(); }, Vector3d::Constant(-1),
      Vector3d::Constant(1), level_set_options, "inverted");
  EXPECT_EQ(error_of([&] { mesh_level_set(inverted, options, "inverted"); }),
            "level set 'inverted' is not positive outside its narrow band (an inverted or "
            "unbounded grid)");
  // The tet-count guard uses the level set's volume.
  EXPECT_NE(error_of([&] {
              mesh_implicit_shape(ImplicitShape::sphere(Vector3d::Zero(), 1.0), 0.05,
                                  coarse_options(1e-4, 0.0));
            }).find("would give about"),
            std::string::npos);
}

}  // namespace
}  // namespace strata
