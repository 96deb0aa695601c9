#include "strata/core/mesh/tet_mesh.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {

namespace {

Vector3d vertex(const TetMesh& mesh, int index) {
  return mesh.vertices.row(index).transpose();
}

}  // namespace

double tet_signed_volume(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                         const Vector3d& x3) {
  return (x1 - x0).dot((x2 - x0).cross(x3 - x0)) / 6.0;
}

double tet_normalized_volume(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                             const Vector3d& x3) {
  const double longest_edge = std::sqrt(
      std::max({(x1 - x0).squaredNorm(), (x2 - x0).squaredNorm(), (x3 - x0).squaredNorm(),
                (x2 - x1).squaredNorm(), (x3 - x1).squaredNorm(), (x3 - x2).squaredNorm()}));
  if (!(longest_edge > 0.0)) return 0.0;
  return 6.0 * std::sqrt(2.0) * tet_signed_volume(x0, x1, x2, x3) /
         (longest_edge * longest_edge * longest_edge);
}

void validate_tet_mesh(const TetMesh& mesh, const std::string& source) {
  const Index num_vertices = mesh.vertices.rows();
  if (mesh.tets.rows() == 0) throw InputError(source + ": mesh has no tetrahedra");
  for (Index v = 0; v < num_vertices; ++v) {
    if (!mesh.vertices.row(v).allFinite())
      throw InputError(source + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
  }
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    for (int k = 0; k < 4; ++k) {
      const int index = mesh.tets(t, k);
      if (index < 0 || index >= num_vertices)
        throw InputError(source + ": tet " + std::to_string(t) + " references vertex " +
                         std::to_string(index) + " (mesh has " + std::to_string(num_vertices) +
                         " vertices)");
      for (int j = 0; j < k; ++j) {
        if (mesh.tets(t, j) == index)
          throw InputError(source + ": tet " + std::to_string(t) + " repeats vertex " +
                           std::to_string(index));
      }
    }
    const double quality =
        tet_normalized_volume(vertex(mesh, mesh.tets(t, 0)), vertex(mesh, mesh.tets(t, 1)),
                              vertex(mesh, mesh.tets(t, 2)), vertex(mesh, mesh.tets(t, 3)));
    if (!(std::abs(quality) >= kDegenerateTetThreshold))
      throw InputError(source + ": tet " + std::to_string(t) +
                       " is degenerate (volume relative to its longest edge cubed: " +
                       std::to_string(quality) + ")");
  }
}

Index orient_tets(TetMesh& mesh) {
  Index flipped = 0;
  for (Index t = 0; t < mesh.tets.rows(); ++t) {
    const double volume =
        tet_signed_volume(vertex(mesh, mesh.tets(t, 0)), vertex(mesh, mesh.tets(t, 1)),
                          vertex(mesh, mesh.tets(t, 2)), vertex(mesh, mesh.tets(t, 3)));
    if (volume < 0.0) {
      std::swap(mesh.tets(t, 2), mesh.tets(t, 3));
      ++flipped;
    }
  }
  return flipped;
}

Index remove_unreferenced_vertices(TetMesh& mesh) {
  std::vector<int> new_index(mesh.vertices.rows(), -1);
  int count = 0;
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (new_index[mesh.tets(t, k)] < 0) new_index[mesh.tets(t, k)] = 0;
  for (auto& index : new_index)
    if (index == 0) index = count++;
  const Index removed = mesh.vertices.rows() - count;
  if (removed == 0) return 0;
  MatrixX3d vertices(count, 3);
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    if (new_index[v] >= 0) vertices.row(new_index[v]) = mesh.vertices.row(v);
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      mesh.tets(t, k) = new_index[mesh.tets(t, k)];
  mesh.vertices = std::move(vertices);
  return removed;
}

MatrixX3i boundary_faces(const MatrixX4i& tets) {
  // Outward faces of a positively oriented tet (0, 1, 2, 3).
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  const Index num_faces = 4 * tets.rows();
  STRATA_VERIFY(tets.size() == 0 || tets.minCoeff() >= 0, "boundary_faces: negative vertex index");
  const Index num_vertices = tets.size() > 0 ? Index(tets.maxCoeff()) + 1 : 0;
  // Faces bucketed by their smallest vertex (a counting sort), each bucket sorted by the other
  // two: the faces in the order of their sorted vertex triples.
  auto face_vertex = [&](Index f, int k) { return tets(f / 4, kFaces[f % 4][k]); };
  auto smallest = [&](Index f) {
    return std::min({face_vertex(f, 0), face_vertex(f, 1), face_vertex(f, 2)});
  };
  std::vector<Index> bucket_start(num_vertices + 1, 0);
  for (Index f = 0; f < num_faces; ++f)
    ++bucket_start[smallest(f) + 1];
  for (Index v = 0; v < num_vertices; ++v)
    bucket_start[v + 1] += bucket_start[v];
  struct Face {
    std::array<int, 2> rest;  ///< the two larger vertices, ascending
    Index face;
  };
  std::vector<Face> faces(num_faces);
  {
    std::vector<Index> next(bucket_start.begin(), bucket_start.end() - 1);
    for (Index f = 0; f < num_faces; ++f) {
      std::array<int, 3> key = {face_vertex(f, 0), face_vertex(f, 1), face_vertex(f, 2)};
      std::sort(key.begin(), key.end());
      faces[next[key[0]]++] = {{key[1], key[2]}, f};
    }
  }
  std::vector<char> boundary(num_faces, 0);
  tbb::parallel_for(Index(0), num_vertices, [&](Index v) {
    const auto begin = faces.begin() + bucket_start[v], end = faces.begin() + bucket_start[v + 1];
    std::sort(begin, end, [](const Face& a, const Face& b) { return a.rest < b.rest; });
    for (auto i = begin; i != end;) {
      auto j = i + 1;
      while (j != end && j->rest == i->rest)
        ++j;
      if (j - i == 1) boundary[i - faces.begin()] = 1;
      i = j;
    }
  });
  MatrixX3i result(std::count(boundary.begin(), boundary.end(), 1), 3);
  Index row = 0;
  for (Index i = 0; i < num_faces; ++i)
    if (boundary[i]) {
      const Index f = faces[i].face;
      result.row(row++) << face_vertex(f, 0), face_vertex(f, 1), face_vertex(f, 2);
    }
  return result;
}

CompressedLists vertex_tets(const MatrixX4i& tets, Index num_vertices) {
  CompressedLists tet_lists;
  tet_lists.offsets.resize(tets.rows() + 1);
  tet_lists.indices.resize(4 * tets.rows());
  for (Index t = 0; t < tets.rows(); ++t) {
    tet_lists.offsets[t + 1] = 4 * (t + 1);
    for (int k = 0; k < 4; ++k) {
      STRATA_VERIFY(tets(t, k) >= 0 && tets(t, k) < num_vertices,
                    "vertex_tets: tet " + std::to_string(t) + " has a vertex out of range");
      tet_lists.indices[4 * t + k] = tets(t, k);
    }
  }
  return transpose_lists(tet_lists, num_vertices);
}

CompressedLists vertex_neighbours(const MatrixX4i& tets, Index num_vertices) {
  const CompressedLists incident = vertex_tets(tets, num_vertices);
  return sorted_unique_lists(num_vertices, num_vertices, [&](Index v, std::vector<int>& out) {
    for (const int t : incident[v])
      for (int k = 0; k < 4; ++k)
        out.push_back(tets(t, k));
  });
}

std::pair<Vector3d, Vector3d> bounding_box(ConstRef<MatrixX3d> points) {
  if (points.rows() == 0) return {Vector3d::Zero(), Vector3d::Zero()};
  return {points.colwise().minCoeff().transpose(), points.colwise().maxCoeff().transpose()};
}

double mesh_volume(const TetMesh& mesh) {
  double volume = 0.0;
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    volume += tet_signed_volume(vertex(mesh, mesh.tets(t, 0)), vertex(mesh, mesh.tets(t, 1)),
                                vertex(mesh, mesh.tets(t, 2)), vertex(mesh, mesh.tets(t, 3)));
  return volume;
}

TetMesh box_tet_mesh(const Vector3d& min, const Vector3d& max, const std::array<int, 3>& cells) {
  for (int axis = 0; axis < 3; ++axis) {
    if (cells[axis] < 1)
      throw InputError("box mesh: cells[" + std::to_string(axis) + "] must be >= 1");
    if (!(max[axis] > min[axis]))
      throw InputError("box mesh: max[" + std::to_string(axis) + "] must exceed min[" +
                       std::to_string(axis) + "]");
  }
  const int nx = cells[0] + 1, ny = cells[1] + 1, nz = cells[2] + 1;
  const auto index = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  TetMesh mesh;
  mesh.vertices.resize(static_cast<Index>(nx) * ny * nz, 3);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Vector3d t(double(i) / cells[0], double(j) / cells[1], double(k) / cells[2]);
        mesh.vertices.row(index(i, j, k)) =
            (min.array() + t.array() * (max - min).array()).matrix();
      }
  // Kuhn split: six tets along paths 000 → e_a → e_a + e_b → 111 over the axis permutations, with
  // each cell mirrored along the axes where its index is odd. Neighbouring cells then share face
  // diagonals (the mesh stays conforming) while the main diagonals alternate, so the mesh has no
  // preferred direction (a single diagonal makes a beam bend sideways under a vertical load).
  static constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                              {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mesh.tets.resize(6 * static_cast<Index>(cells[0]) * cells[1] * cells[2], 4);
  Index t = 0;
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i) {
        const std::array<int, 3> cell = {i, j, k};
        const auto corner_index = [&](const std::array<int, 3>& local) {
          std::array<int, 3> global;
          for (int axis = 0; axis < 3; ++axis)
            global[axis] = cell[axis] + ((cell[axis] & 1) ? 1 - local[axis] : local[axis]);
          return index(global[0], global[1], global[2]);
        };
        for (const auto& permutation : kPermutations) {
          std::array<int, 3> local = {0, 0, 0};
          int tet[4];
          tet[0] = corner_index(local);
          for (int step = 0; step < 3; ++step) {
            local[permutation[step]] = 1;
            tet[step + 1] = corner_index(local);
          }
          if (tet_signed_volume(vertex(mesh, tet[0]), vertex(mesh, tet[1]), vertex(mesh, tet[2]),
                                vertex(mesh, tet[3])) < 0.0)
            std::swap(tet[2], tet[3]);
          mesh.tets.row(t++) << tet[0], tet[1], tet[2], tet[3];
        }
      }
  return mesh;
}

}  // namespace strata
