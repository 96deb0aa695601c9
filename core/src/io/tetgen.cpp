#include "strata/core/io/tetgen.hpp"

#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "strata/core/io/text_tokenizer.hpp"

namespace strata {
namespace {

std::filesystem::path with_extension(std::filesystem::path path, const char* extension) {
  return path.replace_extension(extension);
}

}  // namespace

TetMesh read_tetgen(const std::filesystem::path& path) {
  const std::filesystem::path node_path = with_extension(path, ".node");
  const std::filesystem::path ele_path = with_extension(path, ".ele");

  TextTokenizer node(node_path, '#');
  if (node.at_end()) node.fail("empty file");
  const long long num_vertices = node.next_count("point count", 4);
  if (num_vertices == 0) node.fail("no points (points stored in a .poly file are not supported)");
  node.next_int_in("dimension (must be 3)", 3, 3);
  const long long num_attributes = node.next_int_in("number of point attributes", 0, 1000);
  const long long num_markers = node.next_int_in("number of boundary markers", 0, 1);
  TetMesh mesh;
  mesh.vertices.resize(num_vertices, 3);
  long long first = 0;
  for (long long v = 0; v < num_vertices; ++v) {
    if (v == 0) {
      first = node.next_int_in("first point index", 0, 1);
    } else {
      node.next_int_in("point index (points are numbered consecutively)", first + v, first + v);
    }
    for (int d = 0; d < 3; ++d)
      mesh.vertices(v, d) = node.next_double("point coordinate");
    for (long long a = 0; a < num_attributes + num_markers; ++a)
      node.next_double("point attribute or marker");
  }

  TextTokenizer ele(ele_path, '#');
  if (ele.at_end()) ele.fail("empty file");
  const long long num_tets = ele.next_count("tetrahedron count", 5);
  if (num_tets == 0) ele.fail("no tetrahedra");
  const long long nodes_per_tet = ele.next_int("nodes per tetrahedron");
  if (nodes_per_tet != 4 && nodes_per_tet != 10)
    ele.fail("nodes per tetrahedron must be 4 or 10, got " + std::to_string(nodes_per_tet));
  const long long num_tet_attributes = ele.next_int_in("number of tetrahedron attributes", 0, 1000);
  mesh.tets.resize(num_tets, 4);
  for (long long t = 0; t < num_tets; ++t) {
    ele.next_int("tetrahedron index");
    for (long long k = 0; k < nodes_per_tet; ++k) {
      const long long index =
          ele.next_int_in("tetrahedron node index", first, first + num_vertices - 1);
      if (k < 4) mesh.tets(t, k) = static_cast<int>(index - first);
    }
    for (long long a = 0; a < num_tet_attributes; ++a)
      ele.next_double("tetrahedron attribute");
  }
  return mesh;
}

void write_tetgen(const std::filesystem::path& path, const TetMesh& mesh) {
  write_file_atomically(with_extension(path, ".node"), [&](std::ostream& out) {
    out << mesh.vertices.rows() << " 3 0 0\n";
    for (Index v = 0; v < mesh.vertices.rows(); ++v)
      write_numbered_point(out, v + 1, mesh.vertices.row(v));
  });
  write_file_atomically(with_extension(path, ".ele"), [&](std::ostream& out) {
    out << mesh.tets.rows() << " 4 0\n";
    for (Index t = 0; t < mesh.tets.rows(); ++t)
      out << t + 1 << ' ' << mesh.tets(t, 0) + 1 << ' ' << mesh.tets(t, 1) + 1 << ' '
          << mesh.tets(t, 2) + 1 << ' ' << mesh.tets(t, 3) + 1 << '\n';
  });
}

}  // namespace strata
