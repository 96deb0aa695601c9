// OpenVDB translation unit 1 of 2: LevelSet storage, sampling, .vdb I/O, mesh ↔ volume.
#include "strata/meshing/level_set.hpp"

#include <openvdb/io/File.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <openvdb/tree/LeafManager.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>

#include "level_set_impl.hpp"
#include "strata/core/common/error.hpp"
#include "strata/meshing/triangle_bvh.hpp"

namespace strata {
namespace detail {

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

LevelSet wrap_level_set(openvdb::FloatGrid::Ptr grid) {
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return LevelSet(std::make_unique<LevelSet::Impl>(std::move(grid)));
}

void check_level_set_options(const LevelSetOptions& options, const std::string& what) {
  if (!(options.voxel_size > 0.0) || !std::isfinite(options.voxel_size))
    throw InputError(what + ": voxel size must be a positive number, got " +
                     std::to_string(options.voxel_size));
  if (!(options.half_width >= 1.0) || !std::isfinite(options.half_width))
    throw InputError(what + ": narrow-band half width must be at least 1 voxel, got " +
                     std::to_string(options.half_width));
}

void check_level_set_size(const Vector3d& lo, const Vector3d& hi, const LevelSetOptions& options,
                          const std::string& what) {
  // The estimate is about twice the band of a rounded body; 10⁹ takes several GB in OpenVDB's
  // tree.
  constexpr double kMaxBandVoxels = 1e9;
  const Vector3d extent = (hi - lo).cwiseMax(options.voxel_size);
  const double area =
      2.0 * (extent.x() * extent.y() + extent.y() * extent.z() + extent.z() * extent.x());
  const double voxels =
      area / (options.voxel_size * options.voxel_size) * (2.0 * options.half_width + 1.0);
  if (!(voxels <= kMaxBandVoxels)) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  ": voxel size %g m would need about %.2g voxels for a surface of this size (at "
                  "most 1e9); use a larger voxel_size",
                  options.voxel_size, voxels);
    throw InputError(what + text);
  }
}

}  // namespace detail

namespace {

using UnsafeAccessor = openvdb::tree::ValueAccessor<const openvdb::FloatTree, false>;

openvdb::FloatGrid::Ptr empty_grid() {
  detail::ensure_openvdb_initialized();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(3.0f * 0.01f);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.01));
  grid->setName("level_set");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

}  // namespace

LevelSet::Impl::Impl(openvdb::FloatGrid::Ptr level_set) : grid(std::move(level_set)) {
  const openvdb::FloatTree& tree = grid->tree();
  for (openvdb::FloatTree::LeafCIter leaf = tree.cbeginLeaf(); leaf; ++leaf)
    extent.expand(leaf->getNodeBoundingBox());  // active or not: any voxel may differ
  const float background = tree.background();
  openvdb::FloatTree::ValueAllCIter tile = tree.cbeginValueAll();
  tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1);  // tiles, not voxels
  for (; tile; ++tile)
    if (*tile != background) extent.expand(tile.getBoundingBox());
}

LevelSet::LevelSet() : m_impl(std::make_unique<Impl>(empty_grid())) {}
LevelSet::LevelSet(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
LevelSet::~LevelSet() = default;
LevelSet::LevelSet(const LevelSet& other) : m_impl(std::make_unique<Impl>(*other.m_impl)) {
  m_impl->grid = other.m_impl->grid->deepCopy();
}
LevelSet& LevelSet::operator=(const LevelSet& other) {
  if (this == &other) return *this;
  m_impl = std::make_unique<Impl>(*other.m_impl);
  m_impl->grid = other.m_impl->grid->deepCopy();
  return *this;
}
LevelSet::LevelSet(LevelSet&& other) noexcept = default;
LevelSet& LevelSet::operator=(LevelSet&& other) noexcept = default;

double LevelSet::signed_distance_and_gradient(const Vector3d& p, Vector3d& gradient) const {
  const openvdb::FloatGrid& grid = *m_impl->grid;
  UnsafeAccessor accessor(grid.tree());
  const openvdb::Vec3d x = grid.transform().worldToIndex(openvdb::Vec3d(p(0), p(1), p(2)));
  const openvdb::Coord base(static_cast<int>(std::floor(x[0])), static_cast<int>(std::floor(x[1])),
                            static_cast<int>(std::floor(x[2])));
  const double t[3] = {x[0] - base[0], x[1] - base[1], x[2] - base[2]};
  double value[2][2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        value[i][j][k] = accessor.getValue(base.offsetBy(i, j, k));
  // Trilinear interpolant and its exact partial derivatives (index space).
  double phi = 0.0;
  Vector3d d_index = Vector3d::Zero();
  for (int i = 0; i < 2; ++i) {
    const double wx = i ? t[0] : 1.0 - t[0];
    const double dwx = i ? 1.0 : -1.0;
    for (int j = 0; j < 2; ++j) {
      const double wy = j ? t[1] : 1.0 - t[1];
      const double dwy = j ? 1.0 : -1.0;
      for (int k = 0; k < 2; ++k) {
        const double wz = k ? t[2] : 1.0 - t[2];
        const double dwz = k ? 1.0 : -1.0;
        const double v = value[i][j][k];
        phi += wx * wy * wz * v;
        d_index(0) += dwx * wy * wz * v;
        d_index(1) += wx * dwy * wz * v;
        d_index(2) += wx * wy * dwz * v;
      }
    }
  }
  gradient = d_index / voxel_size();
  return phi;
}

namespace {

/// Catmull-Rom weights of the samples at −1, 0, 1, 2 for a point t ∈ [0, 1) past sample 0, and
/// their derivatives in t.
void catmull_rom_weights(double t, double w[4], double dw[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
  w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
  w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
  dw[0] = 0.5 * (-3.0 * t2 + 4.0 * t - 1.0);
  dw[1] = 0.5 * (9.0 * t2 - 10.0 * t);
  dw[2] = 0.5 * (-9.0 * t2 + 8.0 * t + 1.0);
  dw[3] = 0.5 * (3.0 * t2 - 2.0 * t);
}

}  // namespace

double LevelSet::smooth_signed_distance_and_gradient(const Vector3d& p, Vector3d& gradient) const {
  const openvdb::FloatGrid& grid = *m_impl->grid;
  const openvdb::Vec3d x = grid.transform().worldToIndex(openvdb::Vec3d(p(0), p(1), p(2)));
  if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) {
    gradient.setConstant(std::numeric_limits<double>::quiet_NaN());
    return std::numeric_limits<double>::quiet_NaN();
  }
  // The stencil reads the voxels floor(x) − 1 … floor(x) + 2 on each axis: where they all lie
  // outside the extent, they all hold the background, and so does the interpolant.
  const openvdb::CoordBBox& extent = m_impl->extent;
  for (int a = 0; a < 3; ++a) {
    const double below = std::floor(x[a]);
    if (extent.empty() || !(below + 2.0 >= extent.min()[a] && below - 1.0 <= extent.max()[a])) {
      gradient.setZero();
      return grid.background();
    }
  }
  UnsafeAccessor accessor(grid.tree());
  const openvdb::Coord base(static_cast<int>(std::floor(x[0])), static_cast<int>(std::floor(x[1])),
                            static_cast<int>(std::floor(x[2])));
  double w[3][4], dw[3][4];
  for (int a = 0; a < 3; ++a)
    catmull_rom_weights(x[a] - base[a], w[a], dw[a]);
  double phi = 0.0;
  Vector3d d_index = Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    double plane = 0.0, plane_dy = 0.0, plane_dz = 0.0;
    for (int j = 0; j < 4; ++j) {
      double row = 0.0, row_dz = 0.0;
      for (int k = 0; k < 4; ++k) {
        const double v = accessor.getValue(base.offsetBy(i - 1, j - 1, k - 1));
        row += w[2][k] * v;
        row_dz += dw[2][k] * v;
      }
      plane += w[1][j] * row;
      plane_dy += dw[1][j] * row;
      plane_dz += w[1][j] * row_dz;
    }
    phi += w[0][i] * plane;
    d_index(0) += dw[0][i] * plane;
    d_index(1) += w[0][i] * plane_dy;
    d_index(2) += w[0][i] * plane_dz;
  }
  gradient = d_index / voxel_size();
  return phi;
}

double LevelSet::signed_distance(const Vector3d& p) const {
  Vector3d gradient;
  return signed_distance_and_gradient(p, gradient);
}

Vector3d LevelSet::gradient(const Vector3d& p) const {
  Vector3d gradient;
  signed_distance_and_gradient(p, gradient);
  return gradient;
}

std::pair<Vector3d, Vector3d> LevelSet::bounding_box() const {
  const openvdb::FloatGrid& grid = *m_impl->grid;
  if (grid.activeVoxelCount() == 0) return {Vector3d::Zero(), Vector3d::Zero()};
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  const openvdb::Vec3d lo = grid.indexToWorld(box.min());
  const openvdb::Vec3d hi = grid.indexToWorld(box.max());
  return {Vector3d(lo[0], lo[1], lo[2]), Vector3d(hi[0], hi[1], hi[2])};
}

double LevelSet::voxel_size() const {
  return m_impl->grid->voxelSize()[0];
}
double LevelSet::background() const {
  return m_impl->grid->background();
}
Index LevelSet::num_active_voxels() const {
  return static_cast<Index>(m_impl->grid->activeVoxelCount());
}
std::string LevelSet::name() const {
  return m_impl->grid->getName();
}

SurfaceMesh LevelSet::to_surface(double isovalue, double adaptivity) const {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*m_impl->grid, points, triangles, quads, isovalue, adaptivity);
  SurfaceMesh surface;
  surface.vertices.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v)
    surface.vertices.row(v) = Vector3d(points[v][0], points[v][1], points[v][2]).transpose();
  surface.triangles.resize(static_cast<Index>(triangles.size() + 2 * quads.size()), 3);
  // OpenVDB orients its polygons clockwise seen from outside: reverse to counter-clockwise.
  Index f = 0;
  for (const openvdb::Vec3I& t : triangles)
    surface.triangles.row(f++) << int(t[2]), int(t[1]), int(t[0]);
  for (const openvdb::Vec4I& q : quads) {
    surface.triangles.row(f++) << int(q[2]), int(q[1]), int(q[0]);
    surface.triangles.row(f++) << int(q[3]), int(q[2]), int(q[0]);
  }
  return surface;
}

void LevelSet::write_vdb(const std::filesystem::path& path) const {
  // Written under a temporary name in the same folder, then renamed: readers never see half a file.
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  try {
    openvdb::io::File file(temporary.string());
    file.write(openvdb::GridCPtrVec{m_impl->grid});
    file.close();
    std::filesystem::rename(temporary, path);
  } catch (const std::exception& error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw InputError("cannot write '" + path.string() + "': " + error.what());
  }
}

LevelSet LevelSet::read_vdb(const std::filesystem::path& path, const std::string& grid_name) {
  detail::ensure_openvdb_initialized();
  std::error_code error_code;
  if (!std::filesystem::is_regular_file(path, error_code))
    throw InputError("cannot read '" + path.string() + "': no such file");
  openvdb::GridBase::Ptr base;
  try {
    openvdb::io::File file(path.string());
    file.open(false);  // no delayed loading: the file may change after we return
    if (!grid_name.empty()) {
      if (!file.hasGrid(grid_name))
        throw InputError("cannot read '" + path.string() + "': no grid named '" + grid_name + "'");
      base = file.readGrid(grid_name);
    } else {
      for (openvdb::io::File::NameIterator name = file.beginName(); name != file.endName();
           ++name) {
        openvdb::GridBase::Ptr candidate = file.readGrid(name.gridName());
        if (candidate->isType<openvdb::FloatGrid>()) {
          base = candidate;
          break;
        }
      }
    }
    file.close();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& error) {
    throw InputError("cannot read '" + path.string() + "': not a valid .vdb file (" + error.what() +
                     ")");
  }
  const std::string which = grid_name.empty() ? "no float grid" : "grid '" + grid_name + "'";
  if (!base) throw InputError("cannot read '" + path.string() + "': " + which);
  openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) throw InputError("cannot read '" + path.string() + "': " + which + " is not float");
  if (!grid->transform().isLinear() || !grid->hasUniformVoxels())
    throw InputError("cannot read '" + path.string() + "': grid '" + grid->getName() +
                     "' has no uniform linear transform");
  return detail::wrap_level_set(grid);
}

SurfaceLevelSet surface_to_level_set(const SurfaceMesh& surface, const LevelSetOptions& options) {
  detail::check_level_set_options(options, "surface level set");
  if (surface.vertices.rows() == 0 || surface.triangles.rows() == 0)
    throw InputError("surface level set: the surface is empty");
  if (!surface.vertices.allFinite())
    throw InputError("surface level set: the surface has non-finite vertex coordinates");
  detail::check_level_set_size(surface.vertices.colwise().minCoeff().transpose(),
                               surface.vertices.colwise().maxCoeff().transpose(), options,
                               "surface level set");
  SurfaceLevelSet result;
  result.topology = surface_topology(surface);  // also checks the indices
  detail::ensure_openvdb_initialized();

  const openvdb::math::Transform::Ptr transform =
      openvdb::math::Transform::createLinearTransform(options.voxel_size);
  std::vector<openvdb::Vec3s> points(surface.vertices.rows());
  for (Index v = 0; v < surface.vertices.rows(); ++v) {
    const openvdb::Vec3d x = transform->worldToIndex(
        openvdb::Vec3d(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2)));
    points[v] = openvdb::Vec3s(x);
  }
  std::vector<openvdb::Vec3I> triangles(surface.triangles.rows());
  for (Index f = 0; f < surface.triangles.rows(); ++f)
    triangles[f] =
        openvdb::Vec3I(surface.triangles(f, 0), surface.triangles(f, 1), surface.triangles(f, 2));
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> mesh(points,
                                                                                        triangles);
  const float half_width = static_cast<float>(options.half_width);
  const bool watertight = result.topology.watertight();
  const int flags = watertight ? 0 : openvdb::tools::UNSIGNED_DISTANCE_FIELD;
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      mesh, *transform, half_width, half_width, flags);
  if (!watertight) {
    // Sign every band voxel by the winding number; the flood fill then signs the rest.
    const TriangleBvh bvh(surface.vertices, surface.triangles);
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
      for (auto voxel = leaf.beginValueOn(); voxel; ++voxel) {
        const openvdb::Vec3d x = transform->indexToWorld(voxel.getCoord());
        const double w = bvh.winding_number(Vector3d(x[0], x[1], x[2]));
        const float magnitude = std::abs(*voxel);
        voxel.setValue(w > 0.5 ? -magnitude : magnitude);
      }
    });
    openvdb::tools::signedFloodFill(grid->tree());
    // The fill follows scanlines and leaks through holes: sign every tile (a region without
    // surface) by the winding number at its centre too.
    const float background = grid->background();
    for (auto tile = grid->tree().beginValueOff(); tile; ++tile) {
      if (tile.isVoxelValue()) continue;
      openvdb::CoordBBox box;
      tile.getBoundingBox(box);
      const openvdb::Vec3d x = transform->indexToWorld(box.getCenter());
      tile.setValue(bvh.winding_number(Vector3d(x[0], x[1], x[2])) > 0.5 ? -background
                                                                         : background);
    }
  }
  grid->setName("surface");
  result.level_set = detail::wrap_level_set(grid);
  return result;
}

}  // namespace strata
