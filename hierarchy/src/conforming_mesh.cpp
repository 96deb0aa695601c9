#include "strata/hierarchy/conforming_mesh.hpp"

#include <algorithm>
#include <array>

namespace strata {
namespace {

constexpr std::array<std::array<int, 2>, 6> kEdges{
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

/// Corners of active tets.
std::vector<char> used_vertices(const ActiveCut& cut) {
  const TetTree& tree = cut.tree();
  std::vector<char> used(tree.vertex_capacity(), 0);
  for (NodeId n : cut.nodes())
    for (int v : tree.bey_vertices(n))
      used[v] = 1;
  return used;
}

/// The midpoint of {a, b} if an active tet uses it, else −1.
int used_midpoint(const TetTree& tree, const std::vector<char>& used, int a, int b) {
  const int m = tree.midpoint(a, b);
  return m >= 0 && used[m] ? m : -1;
}

/// Marked edges of `n` as a bit set over kEdges; −1 if `n` must be red-refined (a vertex two
/// levels finer on one of its edges or inside one of its faces).
int marked_pattern(const TetTree& tree, const std::vector<char>& used, NodeId n) {
  const std::array<int, 4>& v = tree.bey_vertices(n);
  int pattern = 0;
  for (int e = 0; e < 6; ++e) {
    const int a = v[kEdges[e][0]], b = v[kEdges[e][1]];
    const int m = used_midpoint(tree, used, a, b);
    if (m < 0) continue;
    if (used_midpoint(tree, used, a, m) >= 0 || used_midpoint(tree, used, m, b) >= 0) return -1;
    pattern |= 1 << e;
  }
  // A face with three marked edges may also hold finer vertices inside it (a neighbour refined
  // its central red triangle): the midpoints of the lines between the edge midpoints.
  for (int k = 0; k < 4; ++k) {
    std::array<int, 3> m{};
    int o = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        if (i != k && j != k) m[o++] = used_midpoint(tree, used, v[i], v[j]);
    if (m[0] < 0 || m[1] < 0 || m[2] < 0) continue;
    if (used_midpoint(tree, used, m[0], m[1]) >= 0 || used_midpoint(tree, used, m[1], m[2]) >= 0 ||
        used_midpoint(tree, used, m[2], m[0]) >= 0)
      return -1;
  }
  return pattern;
}

/// Whether the marked edges are the three of one face.
bool is_face_pattern(int pattern) {
  for (int k = 0; k < 4; ++k) {
    int face = 0;
    for (int e = 0; e < 6; ++e)
      if (kEdges[e][0] != k && kEdges[e][1] != k) face |= 1 << e;
    if (pattern == face) return true;
  }
  return false;
}

/// The triangles of face (a, b, c) split by its marked edges: one marked edge, from its
/// midpoint to the opposite corner; three, the four red triangles; two (ab, ac), the corner
/// triangle at a and the rest cut along the diagonal from the lower-id corner of b, c to the
/// opposite edge's midpoint. Depends only on the face, so both neighbours split it alike.
void split_face(const TetTree& tree, const std::vector<char>& used, std::array<int, 3> f,
                std::vector<std::array<int, 3>>& out) {
  std::array<int, 3> m{};  // m[i]: midpoint of the edge opposite corner i
  int marked = 0;
  for (int i = 0; i < 3; ++i) {
    m[i] = used_midpoint(tree, used, f[(i + 1) % 3], f[(i + 2) % 3]);
    if (m[i] >= 0) ++marked;
  }
  if (marked == 0) {
    out.push_back(f);
  } else if (marked == 3) {
    out.push_back({f[0], m[2], m[1]});
    out.push_back({m[2], f[1], m[0]});
    out.push_back({m[1], m[0], f[2]});
    out.push_back({m[0], m[1], m[2]});
  } else if (marked == 1) {
    const int i = m[0] >= 0 ? 0 : (m[1] >= 0 ? 1 : 2);
    out.push_back({f[i], f[(i + 1) % 3], m[i]});
    out.push_back({f[i], m[i], f[(i + 2) % 3]});
  } else {
    const int i = m[0] < 0 ? 0 : (m[1] < 0 ? 1 : 2);  // the unmarked edge is opposite f[i]
    const int a = f[i], b = f[(i + 1) % 3], c = f[(i + 2) % 3];
    const int mab = m[(i + 2) % 3], mac = m[(i + 1) % 3];
    out.push_back({a, mab, mac});
    if (b < c) {
      out.push_back({mab, b, mac});
      out.push_back({b, c, mac});
    } else {
      out.push_back({mab, b, c});
      out.push_back({mab, c, mac});
    }
  }
}

}  // namespace

ConformingMesh conforming_cut_mesh(ActiveCut& cut) {
  ConformingMesh result;
  TetTree& tree = cut.tree();
  for (;;) {
    const std::vector<char> used = used_vertices(cut);
    std::vector<NodeId> refine;
    for (NodeId n : cut.nodes())
      if (marked_pattern(tree, used, n) < 0) refine.push_back(n);
    if (refine.empty()) break;
    for (NodeId n : refine)
      cut.refine(n);
    result.closure_refinements += static_cast<Index>(refine.size());
  }
  const std::vector<char> used = used_vertices(cut);
  std::vector<int> mesh_vertex(tree.vertex_capacity(), -1);
  for (int v = 0; v < tree.vertex_capacity(); ++v) {
    if (!used[v]) continue;
    mesh_vertex[v] = static_cast<int>(result.tree_vertices.size());
    result.tree_vertices.push_back(v);
  }
  std::vector<Vector3d> positions;
  for (int v : result.tree_vertices)
    positions.push_back(tree.vertex_position(v));
  std::vector<std::array<int, 4>> tets;
  std::vector<int> kinds;
  // Tets hold mesh vertex ids from here on (tree vertices mapped, centres appended).
  const auto emit = [&](std::array<int, 4> t, NodeId n, int kind) {
    const Vector3d a = positions[t[0]];
    const double volume = (positions[t[1]] - a).cross(positions[t[2]] - a).dot(positions[t[3]] - a);
    if (volume < 0.0) std::swap(t[2], t[3]);
    tets.push_back(t);
    result.nodes.push_back(n);
    kinds.push_back(kind);
  };
  const auto mesh_ids = [&](std::array<int, 4> t) {
    for (int& v : t)
      v = mesh_vertex[v];
    return t;
  };
  std::vector<std::array<int, 3>> faces;
  for (NodeId n : cut.sorted_nodes()) {
    const int pattern = marked_pattern(tree, used, n);
    const std::array<int, 4>& v = tree.bey_vertices(n);
    int count = 0, edge = -1;
    for (int e = 0; e < 6; ++e)
      if (pattern & (1 << e)) {
        ++count;
        edge = e;
      }
    if (count == 0) {
      emit(mesh_ids(v), n, 0);
    } else if (count != 1 && !is_face_pattern(pattern)) {
      // Any other pattern: its faces split as above, each joined to the tet's centroid.
      faces.clear();
      for (int k = 0; k < 4; ++k) {
        std::array<int, 3> face{};
        int o = 0;
        for (int j = 0; j < 4; ++j)
          if (j != k) face[o++] = v[j];
        split_face(tree, used, face, faces);
      }
      Vector3d centre = Vector3d::Zero();
      for (int k = 0; k < 4; ++k)
        centre += 0.25 * tree.vertex_position(v[k]);
      const int c = static_cast<int>(positions.size());
      positions.push_back(centre);
      result.tree_vertices.push_back(-1);
      ++result.centres;
      for (const std::array<int, 3>& f : faces)
        emit({mesh_vertex[f[0]], mesh_vertex[f[1]], mesh_vertex[f[2]], c}, n, 3);
    } else if (count == 1) {
      const int a = v[kEdges[edge][0]], b = v[kEdges[edge][1]];
      const int m = tree.midpoint(a, b);
      std::array<int, 2> others{};
      int o = 0;
      for (int k = 0; k < 4; ++k)
        if (k != kEdges[edge][0] && k != kEdges[edge][1]) others[o++] = v[k];
      emit(mesh_ids({a, m, others[0], others[1]}), n, 1);
      emit(mesh_ids({m, b, others[0], others[1]}), n, 1);
    } else {
      int apex = 0;
      for (int k = 0; k < 4; ++k) {
        bool touches = false;
        for (int e = 0; e < 6; ++e)
          if ((pattern & (1 << e)) && (kEdges[e][0] == k || kEdges[e][1] == k)) touches = true;
        if (!touches) apex = k;
      }
      std::array<int, 3> f{};
      int o = 0;
      for (int k = 0; k < 4; ++k)
        if (k != apex) f[o++] = v[k];
      const int m01 = tree.midpoint(f[0], f[1]);
      const int m12 = tree.midpoint(f[1], f[2]);
      const int m20 = tree.midpoint(f[2], f[0]);
      const int d = v[apex];
      emit(mesh_ids({f[0], m01, m20, d}), n, 2);
      emit(mesh_ids({m01, f[1], m12, d}), n, 2);
      emit(mesh_ids({m20, m12, f[2], d}), n, 2);
      emit(mesh_ids({m01, m12, m20, d}), n, 2);
    }
  }
  result.mesh.vertices.resize(static_cast<Index>(positions.size()), 3);
  for (std::size_t i = 0; i < positions.size(); ++i)
    result.mesh.vertices.row(static_cast<Index>(i)) = positions[i].transpose();
  result.mesh.tets.resize(static_cast<Index>(tets.size()), 4);
  result.green.resize(static_cast<Index>(tets.size()));
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (int k = 0; k < 4; ++k)
      result.mesh.tets(static_cast<Index>(t), k) = tets[t][k];
    result.green[static_cast<Index>(t)] = kinds[t];
  }
  return result;
}

}  // namespace strata
