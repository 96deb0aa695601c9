// CGAL Mesh_3 behind tetrahedralize_surface / tetrahedralize_implicit: volumes against exact
// values, boundaries on the input surface, orientation, determinism, and refused input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "meshing_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/mesh/mesh_quality.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/tetrahedralize.hpp"

namespace strata {
namespace {

constexpr double kPi = 3.14159265358979323846;

MeshingOptions coarse_options(double cell_size) {
  MeshingOptions options;
  options.cell_size = cell_size;
  return options;
}

/// Valid, positively oriented, every vertex used.
void expect_clean_mesh(const TetMesh& mesh) {
  ASSERT_GT(mesh.tets.rows(), 0);
  EXPECT_NO_THROW(validate_tet_mesh(mesh, "mesh"));
  std::vector<int> uses(static_cast<std::size_t>(mesh.vertices.rows()), 0);
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const Vector3d x0 = mesh.vertices.row(mesh.tets(t, 0)).transpose();
    EXPECT_GT(tet_signed_volume(x0, mesh.vertices.row(mesh.tets(t, 1)).transpose(),
                                mesh.vertices.row(mesh.tets(t, 2)).transpose(),
                                mesh.vertices.row(mesh.tets(t, 3)).transpose()),
              0.0)
        << "tet " << t;
    for (int k = 0; k < 4; ++k)
      ++uses[static_cast<std::size_t>(mesh.tets(t, k))];
  }
  for (std::size_t v = 0; v < uses.size(); ++v)
    EXPECT_GT(uses[v], 0) << "vertex " << v;
}

/// Distance of p to the surface of the box [lo, hi] (p inside or on it).
double distance_to_box_surface(const Vector3d& p, const Vector3d& lo, const Vector3d& hi) {
  return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

TEST(Tetrahedralize, BoxWithSharpFeaturesHasExactVolumeAndBoundary) {
  const Vector3d lo(0, 0, 0), hi(1, 0.5, 0.25);
  MeshingOptions options = coarse_options(0.1);
  options.sharp_features = true;
  const TetMesh mesh = tetrahedralize_surface(testing::box_surface(lo, hi), options);
  expect_clean_mesh(mesh);
  // Protected edges and corners: every boundary facet lies in a face of the box.
  EXPECT_NEAR(mesh_volume(mesh), 0.125, 1e-12);
  const MatrixX3i faces = boundary_faces(mesh.tets);
  ASSERT_GT(faces.rows(), 0);
  for (Index f = 0; f < faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const Vector3d p = mesh.vertices.row(faces(f, k)).transpose();
      EXPECT_NEAR(distance_to_box_surface(p, lo, hi), 0.0, 1e-12) << "face " << f;
    }
  }
  // The bounding box is the input's: corners are kept.
  const auto [min, max] = bounding_box(mesh.vertices);
  EXPECT_LT((min - lo).norm(), 1e-12);
  EXPECT_LT((max - hi).norm(), 1e-12);
}

TEST(Tetrahedralize, BoxWithoutFeaturesStaysInside) {
  const Vector3d lo(0, 0, 0), hi(1, 1, 1);
  const TetMesh mesh = tetrahedralize_surface(testing::box_surface(lo, hi), coarse_options(0.2));
  expect_clean_mesh(mesh);
  // Boundary vertices lie on the box surface, so the mesh is inscribed: volume ≤ 1, and close
  // to 1 (only edges and corners are cut).
  const double volume = mesh_volume(mesh);
  EXPECT_LE(volume, 1.0 + 1e-12);
  EXPECT_GT(volume, 0.9);
  for (Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Vector3d p = mesh.vertices.row(v).transpose();
    EXPECT_GE(distance_to_box_surface(p, lo, hi), -1e-12) << "vertex " << v;
  }
}

TEST(Tetrahedralize, SameSeedSameMesh) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  MeshingOptions options = coarse_options(0.25);  // with perturb and exude (the defaults)
  const TetMesh a = tetrahedralize_surface(box, options);
  const TetMesh b = tetrahedralize_surface(box, options);
  ASSERT_EQ(a.vertices.rows(), b.vertices.rows());
  ASSERT_EQ(a.tets.rows(), b.tets.rows());
  EXPECT_EQ(a.vertices, b.vertices);  // bit-identical
  EXPECT_EQ(a.tets, b.tets);
}

TEST(Tetrahedralize, ImplicitSphereVolumeConvergesToTheBall) {
  const auto sphere = [](const Vector3d& p) { return p.norm() - 1.0; };
  const Vector3d lo = Vector3d::Constant(-1.2), hi = Vector3d::Constant(1.2);
  double previous_error = 1.0;
  for (const double h : {0.4, 0.2}) {
    MeshingOptions options = coarse_options(h);
    options.facet_distance = h / 20.0;
    const TetMesh mesh = tetrahedralize_implicit(sphere, lo, hi, options);
    expect_clean_mesh(mesh);
    const double error = std::abs(mesh_volume(mesh) - 4.0 * kPi / 3.0) / (4.0 * kPi / 3.0);
    EXPECT_LT(error, 0.05) << "h = " << h;
    EXPECT_LT(error, previous_error) << "h = " << h;
    previous_error = error;
    // Boundary vertices are surface points found by bisection (relative error 1e-6 of the box).
    const MatrixX3i faces = boundary_faces(mesh.tets);
    for (Index f = 0; f < faces.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(mesh.vertices.row(faces(f, k)).norm(), 1.0, 1e-4) << "face " << f;
      }
    }
  }
}

/// The message of the InputError `run` throws ("" if none).
template <typename Run>
std::string error_of(Run run) {
  try {
    run();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(Tetrahedralize, RefusesOpenAndNonManifoldSurfaces) {
  SurfaceMesh open = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  open.triangles.conservativeResize(10, 3);  // drop the +z face
  EXPECT_FALSE(is_closed_manifold_surface(open));
  EXPECT_EQ(error_of([&] { tetrahedralize_surface(open, coarse_options(0.2)); }),
            "surface is not a closed manifold (open, non-manifold or inconsistently oriented): "
            "mesh it through a level set");
  // Two unit boxes sharing the edge x = 1, y = 1: four triangles meet at that edge.
  SurfaceMesh pair = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const SurfaceMesh second = testing::box_surface(Vector3d(1, 1, 0), Vector3d(2, 2, 1));
  pair.vertices.conservativeResize(16, 3);
  pair.vertices.bottomRows(8) = second.vertices;
  pair.triangles.conservativeResize(24, 3);
  pair.triangles.bottomRows(12) = second.triangles.array() + 8;
  // Weld the shared edge's vertices so the surfaces really share it.
  for (Index f = 12; f < 24; ++f) {
    for (int k = 0; k < 3; ++k) {
      for (int v = 0; v < 8; ++v) {
        if (pair.vertices.row(pair.triangles(f, k)) == pair.vertices.row(v)) {
          pair.triangles(f, k) = v;
        }
      }
    }
  }
  EXPECT_FALSE(is_closed_manifold_surface(pair));
  EXPECT_TRUE(
      is_closed_manifold_surface(testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1))));
}

TEST(Tetrahedralize, RefusesRequestsAboveTheTetLimit) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  MeshingOptions options = coarse_options(1e-3);  // ~1e10 tets
  const std::string message = error_of([&] { tetrahedralize_surface(box, options); });
  EXPECT_EQ(message.rfind("meshing: cell_size 0.001 would give about 1e+10 tets", 0), 0u)
      << message;
  EXPECT_DOUBLE_EQ(estimate_tet_count(1.0, options), 1.0 / (kTetsPerCellVolume * 1e-9));
  options.cell_size = 0.0;
  EXPECT_EQ(error_of([&] { tetrahedralize_surface(box, options); }),
            "meshing: cell_size must be > 0");
  EXPECT_EQ(error_of([&] {
              tetrahedralize_implicit([](const Vector3d& p) { return p.norm() - 1; },
                                      Vector3d::Zero(), Vector3d(1, 0, 1), coarse_options(0.1));
            }),
            "implicit domain: the bounding box is empty");
}

TEST(Tetrahedralize, PerturbAndExudeRaiseTheSmallestDihedralAngle) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  MeshingOptions options = coarse_options(0.2);
  options.perturb = false;
  options.exude = false;
  const MeshQuality raw = compute_mesh_quality(tetrahedralize_surface(box, options));
  options.perturb = true;
  options.exude = true;
  const MeshQuality optimised = compute_mesh_quality(tetrahedralize_surface(box, options));
  EXPECT_GE(optimised.min_dihedral_angle, raw.min_dihedral_angle);
  EXPECT_GT(optimised.min_dihedral_angle, 5.0);
}

TEST(TetrahedralizeModels, ArmadilloVolumeMatchesTheSurface) {
  const std::filesystem::path file = std::filesystem::path(STRATA_MODELS_DIR) / "armadillo.off";
  if (!std::filesystem::exists(file)) {
    GTEST_SKIP() << "CGAL models not found in " << STRATA_MODELS_DIR
                 << " (install libcgal-demo, reconfigure)";
  }
  const SurfaceMesh surface = read_surface(file);
  MeshingOptions options = coarse_options(8.0);  // the model is about 120 units tall
  options.facet_distance = 1.0;
  options.perturb = false;  // optimisation is covered on the box; keep this test fast
  options.exude = false;
  const TetMesh mesh = tetrahedralize_surface(surface, options);
  expect_clean_mesh(mesh);
  EXPECT_NEAR(mesh_volume(mesh) / std::abs(enclosed_volume(surface)), 1.0, 0.05);
}

}  // namespace
}  // namespace strata
