// Mesh utilities: the box generator, orientation, validation errors, boundary faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/tet_mesh.hpp"

namespace strata {
namespace {

TEST(BoxTetMesh, CountsVolumeAndPositiveOrientation) {
  const TetMesh mesh = box_tet_mesh(Vector3d(-1, 0, 0), Vector3d(1, 0.5, 0.25), {4, 3, 2});
  EXPECT_EQ(mesh.vertices.rows(), 5 * 4 * 3);
  EXPECT_EQ(mesh.tets.rows(), 6 * 4 * 3 * 2);
  EXPECT_NEAR(mesh_volume(mesh), 2.0 * 0.5 * 0.25, 1e-14);
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const auto x = [&](int k) { return Vector3d(mesh.vertices.row(mesh.tets(t, k))); };
    EXPECT_GT(tet_signed_volume(x(0), x(1), x(2), x(3)), 0.0) << "tet " << t;
  }
  EXPECT_NO_THROW(validate_tet_mesh(mesh, "box"));
}

TEST(BoxTetMesh, IsConformingItsBoundaryIsTheBoxSurface) {
  const int n[3] = {3, 2, 4};
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(3, 2, 4), {n[0], n[1], n[2]});
  const MatrixX3i faces = boundary_faces(mesh.tets);
  // Conforming: only the 2 triangles per boundary quad are unmatched.
  EXPECT_EQ(faces.rows(), 2 * 2 * (n[0] * n[1] + n[1] * n[2] + n[0] * n[2]));
  // Outward orientation: divergence theorem gives the volume; area normals sum to zero.
  double volume = 0.0;
  Vector3d normal_sum = Vector3d::Zero();
  for (Index f = 0; f < faces.rows(); ++f) {
    const Vector3d a = mesh.vertices.row(faces(f, 0)), b = mesh.vertices.row(faces(f, 1)),
                   c = mesh.vertices.row(faces(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
    normal_sum += (b - a).cross(c - a);
  }
  EXPECT_NEAR(volume, 24.0, 1e-12);
  EXPECT_LT(normal_sum.norm(), 1e-12);
}

TEST(BoxTetMesh, EvenCellCountsGiveAMirrorSymmetricMesh) {
  // With alternating diagonals the mesh maps onto itself under reflection in each mid-plane, so a
  // symmetric load cannot produce an asymmetric response.
  const std::array<int, 3> n = {4, 2, 6};
  const TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d(4, 2, 6), n);
  const auto vertex_index = [&](int i, int j, int k) {
    return i + (n[0] + 1) * (j + (n[1] + 1) * k);
  };
  std::set<std::array<int, 4>> tets;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    std::array<int, 4> sorted = {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2),
                                 mesh.tets(t, 3)};
    std::sort(sorted.begin(), sorted.end());
    tets.insert(sorted);
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const auto& tet : tets) {
      std::array<int, 4> mirrored;
      for (int c = 0; c < 4; ++c) {
        const Vector3d p = mesh.vertices.row(tet[c]);
        std::array<int, 3> ijk = {int(std::lround(p[0])), int(std::lround(p[1])),
                                  int(std::lround(p[2]))};
        ijk[axis] = n[axis] - ijk[axis];
        mirrored[c] = vertex_index(ijk[0], ijk[1], ijk[2]);
      }
      std::sort(mirrored.begin(), mirrored.end());
      EXPECT_TRUE(tets.count(mirrored)) << "axis " << axis;
    }
  }
}

TEST(TetMesh, OrientTetsFlipsNegativeTetsAndCountsThem) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  std::swap(mesh.tets(1, 0), mesh.tets(1, 1));
  std::swap(mesh.tets(4, 2), mesh.tets(4, 3));
  EXPECT_EQ(orient_tets(mesh), 2);
  EXPECT_EQ(orient_tets(mesh), 0);
  EXPECT_NEAR(mesh_volume(mesh), 1.0, 1e-14);
}

TEST(TetMesh, ValidationNamesTheSourceAndTheElement) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  const auto message = [](const TetMesh& m) {
    try {
      validate_tet_mesh(m, "beam.msh");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  TetMesh degenerate = mesh;
  degenerate.vertices.row(degenerate.tets(3, 3)) = degenerate.vertices.row(degenerate.tets(3, 0));
  degenerate.vertices.row(degenerate.tets(3, 3)) +=
      1e-12 * Eigen::RowVector3d(1, 0, 0);  // collapse tet 3 (and its neighbours) to ~zero volume
  const std::string degenerate_message = message(degenerate);
  EXPECT_NE(degenerate_message.find("beam.msh"), std::string::npos) << degenerate_message;
  EXPECT_NE(degenerate_message.find("degenerate"), std::string::npos) << degenerate_message;

  TetMesh out_of_range = mesh;
  out_of_range.tets(2, 1) = 99;
  EXPECT_NE(message(out_of_range).find("tet 2"), std::string::npos);

  TetMesh repeated = mesh;
  repeated.tets(5, 1) = repeated.tets(5, 0);
  EXPECT_NE(message(repeated).find("tet 5"), std::string::npos);

  TetMesh empty;
  EXPECT_NE(message(empty).find("no tetrahedra"), std::string::npos);

  TetMesh not_finite = mesh;
  not_finite.vertices(0, 1) = std::nan("");
  EXPECT_NE(message(not_finite).find("vertex 0"), std::string::npos);
}

TEST(TetMesh, RemoveUnreferencedVerticesRenumbers) {
  TetMesh mesh = box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {1, 1, 1});
  const double volume = mesh_volume(mesh);
  mesh.vertices.conservativeResize(mesh.vertices.rows() + 2, 3);
  mesh.vertices.bottomRows(2).setConstant(5.0);
  EXPECT_EQ(remove_unreferenced_vertices(mesh), 2);
  EXPECT_EQ(mesh.vertices.rows(), 8);
  EXPECT_NEAR(mesh_volume(mesh), volume, 1e-15);
}

TEST(BoxTetMesh, RejectsBadArguments) {
  EXPECT_THROW(box_tet_mesh(Vector3d::Zero(), Vector3d::Ones(), {0, 1, 1}), InputError);
  EXPECT_THROW(box_tet_mesh(Vector3d::Ones(), Vector3d::Zero(), {1, 1, 1}), InputError);
}

}  // namespace
}  // namespace strata
