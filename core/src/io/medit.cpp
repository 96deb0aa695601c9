#include "strata/core/io/medit.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <string>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "strata/core/io/text_tokenizer.hpp"

namespace strata {
namespace {

std::string lower(std::string_view token) {
  std::string result(token);
  for (char& c : result)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}

bool is_keyword(std::string_view token) {
  return !token.empty() && std::isalpha(static_cast<unsigned char>(token.front()));
}

}  // namespace

TetMesh read_medit(const std::filesystem::path& path) {
  TextTokenizer in(path, '#');
  if (in.at_end()) in.fail("empty file");
  const std::string source = path.string();
  std::vector<double> coordinates;
  std::vector<long long> tets;
  std::vector<int> tet_lines;
  bool has_vertices = false;
  int dimension = 3;
  while (!in.at_end()) {
    const std::string_view token = in.next("keyword");
    if (!is_keyword(token))
      in.fail("expected a keyword such as Vertices, got '" + std::string(token.substr(0, 40)) +
              "'");
    const std::string keyword = lower(token);
    if (keyword == "end") break;
    if (keyword == "meshversionformatted") {
      in.next_int_in("mesh version", 1, 4);
    } else if (keyword == "dimension") {
      dimension = static_cast<int>(in.next_int("dimension"));
      if (dimension != 3)
        in.fail("only 3D meshes are supported, got Dimension " + std::to_string(dimension));
    } else if (keyword == "vertices") {
      if (has_vertices) in.fail("second Vertices section");
      has_vertices = true;
      const long long count = in.next_count("vertex count", 4);
      coordinates.reserve(3 * count);
      for (long long v = 0; v < count; ++v) {
        for (int d = 0; d < 3; ++d)
          coordinates.push_back(in.next_double("vertex coordinate"));
        in.next_int("vertex reference");
      }
    } else if (keyword == "tetrahedra") {
      const long long count = in.next_count("tetrahedron count", 5);
      for (long long t = 0; t < count; ++t) {
        for (int k = 0; k < 4; ++k)
          tets.push_back(
              in.next_int_in("tetrahedron vertex index", 1, std::numeric_limits<int>::max()));
        tet_lines.push_back(in.line());
        in.next_int("tetrahedron reference");
      }
    } else {
      // Triangles, Edges, Corners, Ridges, Normals, ...: numbers up to the next keyword.
      while (!in.at_end() && !is_keyword(in.peek()))
        in.next("section entry");
    }
  }
  if (!has_vertices) throw InputError(source + ": no Vertices section");
  if (tets.empty()) throw InputError(source + ": no Tetrahedra in the file");

  TetMesh mesh;
  const Index num_vertices = static_cast<Index>(coordinates.size() / 3);
  mesh.vertices.resize(num_vertices, 3);
  for (Index v = 0; v < num_vertices; ++v)
    for (int d = 0; d < 3; ++d)
      mesh.vertices(v, d) = coordinates[3 * v + d];
  const Index num_tets = static_cast<Index>(tets.size() / 4);
  mesh.tets.resize(num_tets, 4);
  for (Index t = 0; t < num_tets; ++t)
    for (int k = 0; k < 4; ++k) {
      const long long index = tets[4 * t + k];
      if (index > num_vertices)
        throw InputError(source + ":" + std::to_string(tet_lines[t]) + ": tetrahedron " +
                         std::to_string(t + 1) + " references vertex " + std::to_string(index) +
                         " but there are " + std::to_string(num_vertices) + " vertices");
      mesh.tets(t, k) = static_cast<int>(index - 1);
    }
  return mesh;
}

void write_medit(const std::filesystem::path& path, const TetMesh& mesh) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "MeshVersionFormatted 2\nDimension 3\nVertices\n" << mesh.vertices.rows() << '\n';
    for (Index v = 0; v < mesh.vertices.rows(); ++v) {
      for (int d = 0; d < 3; ++d) {
        write_double(out, mesh.vertices(v, d));
        out << ' ';
      }
      out << "0\n";
    }
    out << "Tetrahedra\n" << mesh.tets.rows() << '\n';
    for (Index t = 0; t < mesh.tets.rows(); ++t)
      out << mesh.tets(t, 0) + 1 << ' ' << mesh.tets(t, 1) + 1 << ' ' << mesh.tets(t, 2) + 1 << ' '
          << mesh.tets(t, 3) + 1 << " 1\n";
    out << "End\n";
  });
}

}  // namespace strata
