// Surface file → tet mesh: routing (polyhedral or level set), the mesh cache and the reports.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "meshing_test_utils.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/mesh_cache.hpp"
#include "strata/meshing/mesh_surface_file.hpp"
#include "strata/meshing/surface_io.hpp"
#include "strata/meshing/tetrahedralize.hpp"

namespace strata {
namespace {

class MeshSurfaceFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_folder = std::filesystem::temp_directory_path() /
               ("strata_mesh_surface_file_" + std::string(info->name()) + "_" +
                std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    std::filesystem::remove_all(m_folder);
    std::filesystem::create_directories(m_folder);
  }
  void TearDown() override { std::filesystem::remove_all(m_folder); }

  /// Writes `surface` as OFF; the first `num_triangles` triangles (all when < 0).
  std::filesystem::path write_off(const std::string& name, const SurfaceMesh& surface,
                                  Index num_triangles = -1) const {
    if (num_triangles < 0) num_triangles = surface.triangles.rows();
    const std::filesystem::path path = m_folder / name;
    std::ofstream out(path);
    out.precision(17);
    out << "OFF\n" << surface.vertices.rows() << " " << num_triangles << " 0\n";
    for (Index v = 0; v < surface.vertices.rows(); ++v)
      out << surface.vertices.row(v) << "\n";
    for (Index f = 0; f < num_triangles; ++f)
      out << "3 " << surface.triangles.row(f) << "\n";
    return path;
  }

  std::filesystem::path m_folder;
};

MeshingOptions options_with_cell_size(double h) {
  MeshingOptions options;
  options.cell_size = h;
  return options;
}

TEST_F(MeshSurfaceFile, ClosedSurfaceTakesThePolyhedralRoute) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(2, 1, 1));
  const SurfaceMeshingResult result =
      mesh_surface_file(write_off("box.off", box), options_with_cell_size(0.25));
  EXPECT_EQ(result.report.route, "polyhedral");
  EXPECT_TRUE(result.warning.empty());
  EXPECT_TRUE(result.surface.closed);
  EXPECT_EQ(result.surface.triangles, 12);
  EXPECT_DOUBLE_EQ(result.surface.enclosed_volume, 2.0);
  EXPECT_FALSE(result.report.from_cache);
  EXPECT_EQ(result.report.quality.tets, result.mesh.tets.rows());
  EXPECT_DOUBLE_EQ(result.report.quality.total_volume, mesh_volume(result.mesh));
  EXPECT_NEAR(result.report.volume_ratio(), 1.0, 0.05);
  EXPECT_EQ(result.report.quality.negative_tets, 0);
}

TEST_F(MeshSurfaceFile, CacheReturnsTheSameMeshAndKeysOnContentAndOptions) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const std::filesystem::path file = write_off("box.off", box);
  const MeshCache cache(m_folder / "cache");
  const MeshingOptions options = options_with_cell_size(0.3);
  const SurfaceMeshingResult first = mesh_surface_file(file, options, &cache);
  EXPECT_FALSE(first.report.from_cache);
  EXPECT_TRUE(std::filesystem::exists(cache.entry_path(first.cache_key)));
  const SurfaceMeshingResult second = mesh_surface_file(file, options, &cache);
  EXPECT_TRUE(second.report.from_cache);
  EXPECT_EQ(second.mesh.vertices, first.mesh.vertices);  // .vtu numbers are round-trip exact
  EXPECT_EQ(second.mesh.tets, first.mesh.tets);

  MeshingOptions other = options;
  other.seed = 1;
  EXPECT_NE(meshing_cache_key(file, other, "polyhedral"), first.cache_key);
  other = options;
  other.facet_angle = 20.0;
  EXPECT_NE(meshing_cache_key(file, other, "polyhedral"), first.cache_key);
  EXPECT_NE(meshing_cache_key(file, options, "level set"), first.cache_key);
  const SurfaceMesh moved = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1.5));
  EXPECT_NE(meshing_cache_key(write_off("box.off", moved), options, "polyhedral"), first.cache_key);
}

TEST_F(MeshSurfaceFile, CorruptCacheEntryIsAMiss) {
  const std::filesystem::path file =
      write_off("box.off", testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1)));
  const MeshCache cache(m_folder / "cache");
  const MeshingOptions options = options_with_cell_size(0.3);
  const std::string key = meshing_cache_key(file, options, "polyhedral");
  std::filesystem::create_directories(cache.folder());
  std::ofstream(cache.entry_path(key)) << "<VTKFile truncated";
  EXPECT_FALSE(cache.load(key).has_value());
  const SurfaceMeshingResult result = mesh_surface_file(file, options, &cache);
  EXPECT_FALSE(result.report.from_cache);
  EXPECT_TRUE(cache.load(key).has_value());  // overwritten by a good entry
}

TEST_F(MeshSurfaceFile, OpenSurfaceGoesThroughALevelSetWithAWarning) {
  // The unit cube without its +z face (last two triangles): the winding number closes the hole.
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const std::filesystem::path file = write_off("open.off", box, 10);
  const SurfaceMeshingResult result = mesh_surface_file(file, options_with_cell_size(0.2));
  EXPECT_EQ(result.report.route, "level set");
  EXPECT_FALSE(result.surface.closed);
  EXPECT_EQ(result.surface.topology.boundary_edges, 4);
  EXPECT_EQ(result.report.surface_volume, 0.0);  // no enclosed volume to compare with
  EXPECT_EQ(result.warning.rfind(file.string() + ": surface not watertight", 0), 0u)
      << result.warning;
  EXPECT_NO_THROW(validate_tet_mesh(result.mesh, "level-set mesh"));
  EXPECT_NEAR(mesh_volume(result.mesh), 1.0, 0.1);
}

std::string error_of(const std::filesystem::path& file, const MeshingOptions& options) {
  try {
    mesh_surface_file(file, options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST_F(MeshSurfaceFile, ErrorsNameTheFile) {
  const std::filesystem::path missing = m_folder / "missing.stl";
  EXPECT_EQ(error_of(missing, options_with_cell_size(0.1)), missing.string() + ": no such file");
  const std::filesystem::path box =
      write_off("box.off", testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1)));
  EXPECT_EQ(error_of(box, options_with_cell_size(0.001))
                .rfind(box.string() + ": meshing: cell_size 0.001 would give about 1e+10 tets", 0),
            0u);
  MeshingOptions options = options_with_cell_size(0.1);
  options.facet_angle = 40.0;
  EXPECT_EQ(error_of(box, options),
            box.string() + ": meshing: facet_angle must be in (0, 30] degrees");
}

/// Two closed boxes in one file that overlap: each closed and manifold, together self-intersecting.
SurfaceMesh overlapping_boxes() {
  const SurfaceMesh a = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const SurfaceMesh b = testing::box_surface(Vector3d(0.5, 0.25, 0.25), Vector3d(1.5, 0.75, 0.75));
  SurfaceMesh both;
  both.vertices.resize(a.vertices.rows() + b.vertices.rows(), 3);
  both.vertices << a.vertices, b.vertices;
  both.triangles.resize(a.triangles.rows() + b.triangles.rows(), 3);
  both.triangles << a.triangles,
      (b.triangles.array() + static_cast<int>(a.vertices.rows())).matrix();
  return both;
}

TEST_F(MeshSurfaceFile, SelfIntersectingClosedSurfaceTakesTheLevelSetRoute) {
  const SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  EXPECT_FALSE(surface_self_intersects(box));
  const SurfaceMesh both = overlapping_boxes();
  ASSERT_TRUE(is_closed_manifold_surface(both));
  EXPECT_TRUE(surface_self_intersects(both));
  const SurfaceMeshingResult result =
      mesh_surface_file(write_off("overlap.off", both), options_with_cell_size(0.2));
  EXPECT_EQ(result.report.route, "level set");
  EXPECT_NE(result.warning.find("intersects itself"), std::string::npos) << result.warning;
  // The level set meshes the union: 1 + 0.5 · 0.5 · 0.5 (the part of the second box outside the
  // first), within the meshing tolerance of a 0.2 cell size on a 1.5 m body.
  double volume = 0.0;
  for (Index t = 0; t < result.mesh.tets.rows(); ++t) {
    const Vector3d x0 = result.mesh.vertices.row(result.mesh.tets(t, 0)).transpose();
    volume += (result.mesh.vertices.row(result.mesh.tets(t, 1)).transpose() - x0)
                  .cross(result.mesh.vertices.row(result.mesh.tets(t, 2)).transpose() - x0)
                  .dot(result.mesh.vertices.row(result.mesh.tets(t, 3)).transpose() - x0) /
              6.0;
  }
  EXPECT_NEAR(volume, 1.125, 0.1);
}

TEST(MeshingReport, SurfaceReportCountsDefects) {
  SurfaceMesh box = testing::box_surface(Vector3d(0, 0, 0), Vector3d(1, 2, 3));
  SurfaceReport report = describe_surface(box);
  EXPECT_EQ(report.vertices, 8);
  EXPECT_EQ(report.triangles, 12);
  EXPECT_TRUE(report.closed);
  EXPECT_DOUBLE_EQ(report.enclosed_volume, 6.0);
  EXPECT_EQ(report.bbox_max, Vector3d(1, 2, 3));
  EXPECT_NE(format_surface_report(report).find("closed            yes (0 boundary edges)"),
            std::string::npos);
  box.triangles.conservativeResize(11, 3);
  report = describe_surface(box);
  EXPECT_FALSE(report.closed);
  EXPECT_EQ(report.topology.boundary_edges, 3);
  EXPECT_NE(format_surface_report(report).find("closed            no (3 boundary edges)"),
            std::string::npos);
}

}  // namespace
}  // namespace strata
