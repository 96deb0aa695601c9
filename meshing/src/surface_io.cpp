// CGAL's polygon-soup readers behind read_surface (the only CGAL I/O translation unit).
#include "strata/meshing/surface_io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OBJ.h>
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

std::string lower_extension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// Runs CGAL's reader for `extension`; false when parsing failed.
bool read_polygon_soup(const std::string& file, const std::string& extension,
                       std::vector<Point>& points,
                       std::vector<std::vector<std::size_t>>& polygons) {
  if (extension == ".off") return CGAL::IO::read_OFF(file, points, polygons);
  if (extension == ".obj") return CGAL::IO::read_OBJ(file, points, polygons);
  if (extension == ".ply") return CGAL::IO::read_PLY(file, points, polygons);
  std::vector<std::array<std::size_t, 3>> triangles;
  const bool ok = CGAL::IO::read_STL(file, points, triangles);
  for (const auto& triangle : triangles) {
    polygons.push_back({triangle[0], triangle[1], triangle[2]});
  }
  return ok;
}

/// read_polygon_soup with std::cerr swallowed: some readers print their own diagnostics there, and
/// the caller reports one line. (std::cerr is process-wide: do not read surfaces concurrently with
/// other output to std::cerr.)
bool read_polygon_soup_quietly(const std::string& file, const std::string& extension,
                               std::vector<Point>& points,
                               std::vector<std::vector<std::size_t>>& polygons) {
  std::ostringstream sink;
  std::streambuf* const original = std::cerr.rdbuf(sink.rdbuf());
  try {
    const bool ok = read_polygon_soup(file, extension, points, polygons);
    std::cerr.rdbuf(original);
    return ok;
  } catch (...) {
    std::cerr.rdbuf(original);
    return false;
  }
}

}  // namespace

SurfaceMesh read_surface(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::string extension = lower_extension(path);
  if (extension != ".off" && extension != ".obj" && extension != ".ply" && extension != ".stl") {
    throw InputError(file + ": unknown surface format \"" + path.extension().string() +
                     "\" (expected .off, .obj, .ply or .stl)");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(file + ": no such file");
  }
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  if (!read_polygon_soup_quietly(file, extension, points, polygons)) {
    throw InputError(file + ": cannot parse as " + extension.substr(1) + " (malformed file)");
  }

  SurfaceMesh surface;
  surface.vertices.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double x = CGAL::to_double(points[i][k]);
      if (!std::isfinite(x)) {
        throw InputError(file + ": vertex " + std::to_string(i) + " has a non-finite coordinate");
      }
      surface.vertices(static_cast<Index>(i), k) = x;
    }
  }
  std::vector<std::array<int, 3>> triangles;
  for (std::size_t p = 0; p < polygons.size(); ++p) {
    const std::vector<std::size_t>& polygon = polygons[p];
    for (const std::size_t v : polygon) {
      if (v >= points.size()) {
        throw InputError(file + ": polygon " + std::to_string(p) + " has vertex index " +
                         std::to_string(v) + " out of range (" + std::to_string(points.size()) +
                         " vertices)");
      }
    }
    if (polygon.size() < 3) {
      throw InputError(file + ": polygon " + std::to_string(p) + " has fewer than 3 vertices");
    }
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
      triangles.push_back({static_cast<int>(polygon[0]), static_cast<int>(polygon[k]),
                           static_cast<int>(polygon[k + 1])});
    }
  }
  if (triangles.empty()) throw InputError(file + ": the surface has no triangles");
  surface.triangles.resize(static_cast<Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (int k = 0; k < 3; ++k)
      surface.triangles(static_cast<Index>(f), k) = triangles[f][k];
  }
  Index degenerate = 0;
  for (Index f = 0; f < surface.triangles.rows(); ++f) {
    degenerate += is_degenerate_triangle(surface, f) ? 1 : 0;
  }
  if (degenerate == surface.triangles.rows()) {
    throw InputError(file + ": all " + std::to_string(degenerate) +
                     " triangles are degenerate (zero area)");
  }
  return surface;
}

bool surface_self_intersects(const SurfaceMesh& surface) {
  std::vector<Point> points;
  points.reserve(static_cast<size_t>(surface.vertices.rows()));
  for (Index v = 0; v < surface.vertices.rows(); ++v)
    points.emplace_back(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2));
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(static_cast<size_t>(surface.triangles.rows()));
  for (Index t = 0; t < surface.triangles.rows(); ++t)
    polygons.push_back({static_cast<std::size_t>(surface.triangles(t, 0)),
                        static_cast<std::size_t>(surface.triangles(t, 1)),
                        static_cast<std::size_t>(surface.triangles(t, 2))});
  namespace PMP = CGAL::Polygon_mesh_processing;
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
    throw std::logic_error("surface_self_intersects: the surface is not an oriented manifold");
  CGAL::Surface_mesh<Point> mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return PMP::does_self_intersect(mesh);
}

}  // namespace strata
