#include "strata/hierarchy/finest_level.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "strata/core/common/error.hpp"
#include "strata/core/mesh/point_location.hpp"
#include "strata/hierarchy/tree_point_location.hpp"

namespace strata {
namespace {

/// The same inclusive, widened tests as select_vertices (region.hpp), for one point.
bool region_contains(const Region& region, const Vector3d& x, double tolerance) {
  if (const auto* box = std::get_if<BoxRegion>(&region))
    return ((box->min.array() - tolerance) <= x.array()).all() &&
           (x.array() <= (box->max.array() + tolerance)).all();
  if (const auto* plane = std::get_if<PlaneRegion>(&region))
    return std::abs(plane->normal.normalized().dot(x - plane->point)) <=
           plane->distance + tolerance;
  const auto& sphere = std::get<SphereRegion>(region);
  return (x - sphere.center).norm() <= sphere.radius + tolerance;
}

/// Whether the ball (center, radius) may reach into the widened region.
bool region_near(const Region& region, const Vector3d& center, double radius, double tolerance) {
  if (const auto* box = std::get_if<BoxRegion>(&region)) {
    const Vector3d nearest = center.cwiseMax(box->min).cwiseMin(box->max);
    return (center - nearest).norm() <= radius + tolerance;
  }
  if (const auto* plane = std::get_if<PlaneRegion>(&region))
    return std::abs(plane->normal.normalized().dot(center - plane->point)) <=
           plane->distance + radius + tolerance;
  const auto& sphere = std::get<SphereRegion>(region);
  return (center - sphere.center).norm() <= sphere.radius + radius + tolerance;
}

struct Ball {
  Vector3d center;
  double radius;
};

Ball bounding_ball(const Matrix3x4d& x) {
  const Vector3d center = x.rowwise().mean();
  return {center, (x.colwise() - center).colwise().norm().maxCoeff()};
}

/// Calls visit(λ) for the lattice points λ = (i, j, k, l)/m, i + j + k + l = m, of a tet.
template <typename Visit>
void for_each_lattice_point(int m, Visit&& visit) {
  for (int i = 0; i <= m; ++i)
    for (int j = 0; i + j <= m; ++j)
      for (int k = 0; i + j + k <= m; ++k) {
        const int l = m - i - j - k;
        visit(Eigen::Vector4d(i, j, k, l) / static_cast<double>(m));
      }
}

/// A coarse boundary triangle and the root tet it bounds (its corners' tree vertices, ascending).
struct BoundaryTriangle {
  NodeId root;
  Vector3d corner[3];
  std::array<int, 3> vertex{-1, -1, -1};
};

std::vector<BoundaryTriangle> coarse_boundary(const TetTree& tree) {
  std::map<std::array<int, 3>, std::pair<int, NodeId>> faces;  // sorted key → (count, root)
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (NodeId r = 0; r < tree.num_roots(); ++r) {
    const std::array<int, 4> v = tree.tet_vertices(r);
    for (const auto& face : kFace) {
      std::array<int, 3> key = {v[face[0]], v[face[1]], v[face[2]]};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key, 0, r);
      ++it->second.first;
    }
  }
  std::vector<BoundaryTriangle> boundary;
  for (const auto& [key, use] : faces)
    if (use.first == 1) {
      BoundaryTriangle triangle{use.second, {}, key};
      for (int c = 0; c < 3; ++c)
        triangle.corner[c] = tree.vertex_position(key[c]);
      boundary.push_back(triangle);
    }
  return boundary;
}

/// Finest sub-triangles (levels more midpoint splits) of a triangle whose corners all lie in the
/// region; appends them with their areas.
void collect_finest_triangles(const Region& region, double tolerance, NodeId root,
                              const Vector3d& a, const Vector3d& b, const Vector3d& c, int levels,
                              std::vector<BoundaryTriangle>& out, std::vector<double>& areas) {
  Matrix3x4d corners;
  corners << a, b, c, a;
  const Ball ball = bounding_ball(corners);
  if (!region_near(region, ball.center, ball.radius, tolerance)) return;
  if (levels == 0) {
    if (region_contains(region, a, tolerance) && region_contains(region, b, tolerance) &&
        region_contains(region, c, tolerance)) {
      out.push_back({root, {a, b, c}});
      areas.push_back(0.5 * (b - a).cross(c - a).norm());
    }
    return;
  }
  const Vector3d ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  collect_finest_triangles(region, tolerance, root, a, ab, ca, levels - 1, out, areas);
  collect_finest_triangles(region, tolerance, root, ab, b, bc, levels - 1, out, areas);
  collect_finest_triangles(region, tolerance, root, ca, bc, c, levels - 1, out, areas);
  collect_finest_triangles(region, tolerance, root, ab, bc, ca, levels - 1, out, areas);
}

/// Finest lattice points of all roots inside the region, without duplicates (points shared by
/// neighbouring roots are merged by their position quantised to 10³ × tolerance).
std::vector<RootPoint> finest_lattice_points(const TetTree& tree, const Region& region,
                                             double tolerance) {
  const int m = 1 << tree.max_level();
  const double quantum = std::max(1e3 * tolerance, 1e-300);
  std::map<std::tuple<long long, long long, long long>, RootPoint> unique;
  for (NodeId r = 0; r < tree.num_roots(); ++r) {
    const Matrix3x4d x = tree.tet_positions(r);
    const Ball ball = bounding_ball(x);
    if (!region_near(region, ball.center, ball.radius, tolerance)) continue;
    for_each_lattice_point(m, [&](const Eigen::Vector4d& lambda) {
      const Vector3d p = x * lambda;
      if (!region_contains(region, p, tolerance)) return;
      const auto key = std::make_tuple(std::llround(p.x() / quantum), std::llround(p.y() / quantum),
                                       std::llround(p.z() / quantum));
      unique.try_emplace(key, RootPoint{r, p});
    });
  }
  std::vector<RootPoint> points;
  points.reserve(unique.size());
  for (const auto& [key, point] : unique)
    points.push_back(point);
  return points;
}

}  // namespace

CutPointWeights embed_point(const ActiveCut& cut, const FlatTreeMesh& flat,
                            const RootPoint& point) {
  const TetTree& tree = cut.tree();
  NodeId node = point.root;
  while (!cut.is_active(node)) {
    if (tree.is_leaf(node))
      throw std::logic_error("embed_point: no active node above leaf " + std::to_string(node));
    node = descend_to_point(tree, node, point.position, tree.level(node) + 1).node;
  }
  CutPointWeights result;
  result.node = node;
  const Matrix3x4d x = tree.tet_positions(node);
  result.weights =
      tet_barycentric_coordinates(point.position, x.col(0), x.col(1), x.col(2), x.col(3));
  const std::array<int, 4> corners = tree.tet_vertices(node);
  for (int k = 0; k < 4; ++k) {
    result.vertices[k] = flat.mesh_vertices[corners[k]];
    if (result.vertices[k] < 0)
      throw std::logic_error("embed_point: flat mesh does not match the cut");
  }
  return result;
}

std::vector<CutPointWeights> embed_points(const ActiveCut& cut, const FlatTreeMesh& flat,
                                          const std::vector<RootPoint>& points) {
  std::vector<CutPointWeights> result;
  result.reserve(points.size());
  for (const RootPoint& point : points)
    result.push_back(embed_point(cut, flat, point));
  return result;
}

std::vector<RootPoint> finest_boundary_points(const TetTree& tree) {
  // On a coarse boundary triangle (a, b, c) the finest level's vertices are the points
  // (k a + i b + j c) / n, i + j + k = n = 2^L (midpoint splits, L times). A point on an edge or
  // corner shared by two triangles has the same non-zero weights on the same tree vertices in
  // both: that list is its key.
  const int n = 1 << tree.max_level();
  std::vector<RootPoint> points;
  std::set<std::array<int, 6>> seen;
  for (const BoundaryTriangle& face : coarse_boundary(tree))
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const int weight[3] = {n - i - j, i, j};
        std::array<int, 6> key{-1, 0, -1, 0, -1, 0};  // (vertex, weight) × 3, vertices ascending
        for (int c = 0, used = 0; c < 3; ++c)
          if (weight[c] > 0) {
            key[2 * used] = face.vertex[c];
            key[2 * used + 1] = weight[c];
            ++used;
          }
        if (!seen.insert(key).second) continue;
        const Vector3d position =
            (weight[0] * face.corner[0] + weight[1] * face.corner[1] + weight[2] * face.corner[2]) /
            static_cast<double>(n);
        points.push_back({face.root, position});
      }
  return points;
}

std::vector<PointLoad> finest_level_loads(const TetTree& tree, const std::vector<RegionLoad>& loads,
                                          double tolerance) {
  std::vector<PointLoad> result;
  if (loads.empty()) return result;
  const std::vector<BoundaryTriangle> boundary = coarse_boundary(tree);
  for (const RegionLoad& load : loads) {
    validate_region(load.region, load.name + ".region");
    if (!load.total_force.allFinite()) throw InputError(load.name + ": total_force must be finite");
    std::vector<BoundaryTriangle> triangles;
    std::vector<double> areas;
    for (const BoundaryTriangle& face : boundary)
      collect_finest_triangles(load.region, tolerance, face.root, face.corner[0], face.corner[1],
                               face.corner[2], tree.max_level(), triangles, areas);
    double area_sum = 0.0;
    for (double area : areas)
      area_sum += area;
    if (!triangles.empty() && area_sum > 0.0) {
      const double traction = load.total_force.norm() / area_sum;
      for (size_t k = 0; k < triangles.size(); ++k) {
        const Vector3d share = load.total_force * (areas[k] / area_sum / 3.0);
        for (int c = 0; c < 3; ++c)
          result.push_back({{triangles[k].root, triangles[k].corner[c]}, share, traction});
      }
      continue;
    }
    const std::vector<RootPoint> points = finest_lattice_points(tree, load.region, tolerance);
    if (points.empty()) throw InputError(load.name + ": region selects no vertex");
    const Vector3d share = load.total_force / static_cast<double>(points.size());
    for (const RootPoint& point : points)
      result.push_back({point, share, 0.0});
  }
  return result;
}

VectorXd map_point_loads(const ActiveCut& cut, const FlatTreeMesh& flat,
                         const std::vector<PointLoad>& loads, VectorXd* tet_traction) {
  VectorXd forces = VectorXd::Zero(3 * flat.mesh.vertices.rows());
  std::vector<int> tet_of_node;
  if (tet_traction) {
    tet_traction->setZero(static_cast<Index>(flat.tet_nodes.size()));
    tet_of_node.assign(cut.tree().pool_size(), -1);
    for (size_t t = 0; t < flat.tet_nodes.size(); ++t)
      tet_of_node[flat.tet_nodes[t]] = static_cast<int>(t);
  }
  for (const PointLoad& load : loads) {
    const CutPointWeights w = embed_point(cut, flat, load.point);
    for (int k = 0; k < 4; ++k)
      forces.segment<3>(3 * w.vertices[k]) += w.weights[k] * load.force;
    if (tet_traction) {
      double& traction = (*tet_traction)[tet_of_node[w.node]];
      traction = std::max(traction, load.traction);
    }
  }
  return forces;
}

bool dirichlet_exact_on(const TetTree& tree, NodeId n, const std::vector<DirichletSpec>& groups,
                        double tolerance) {
  const int remaining = tree.max_level() - tree.level(n);
  if (remaining <= 0 || groups.empty()) return true;
  const Matrix3x4d x = tree.tet_positions(n);
  const Ball ball = bounding_ball(x);
  std::vector<int> near;  // groups whose region may reach this tet
  for (int g = 0; g < static_cast<int>(groups.size()); ++g)
    if (region_near(groups[g].region, ball.center, ball.radius, tolerance)) near.push_back(g);
  if (near.empty()) return true;
  // Owner of a point: the last group whose region holds it (later groups win, dirichlet.hpp).
  const auto owner = [&](const Vector3d& p) {
    int result = -1;
    for (int g : near)
      if (region_contains(groups[g].region, p, tolerance)) result = g;
    return result;
  };
  std::array<int, 4> corner_owner{};
  for (int k = 0; k < 4; ++k)
    corner_owner[k] = owner(x.col(k));
  // One group owns every corner and no later group reaches the tet: regions are convex, so it owns
  // every point of the tet.
  if (corner_owner[0] >= 0 && corner_owner[0] == near.back() &&
      corner_owner[0] == corner_owner[1] && corner_owner[0] == corner_owner[2] &&
      corner_owner[0] == corner_owner[3])
    return true;
  bool exact = true;
  for_each_lattice_point(1 << remaining, [&](const Eigen::Vector4d& lambda) {
    if (!exact) return;
    const int g = owner(x * lambda);
    if (g < 0) return;
    for (int k = 0; k < 4; ++k)
      if (lambda[k] > 0.0 && corner_owner[k] != g) exact = false;
  });
  return exact;
}

std::vector<NodeId> inexact_dirichlet_nodes(const ActiveCut& cut,
                                            const std::vector<DirichletSpec>& groups,
                                            double tolerance) {
  std::vector<NodeId> result;
  if (groups.empty()) return result;
  for (NodeId n : cut.sorted_nodes())
    if (!dirichlet_exact_on(cut.tree(), n, groups, tolerance)) result.push_back(n);
  return result;
}

}  // namespace strata
