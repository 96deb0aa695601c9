#include "strata/core/io/gmsh.hpp"

#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"
#include "strata/core/io/text_tokenizer.hpp"

namespace strata {
namespace {

constexpr int kGmshTet = 4;
constexpr long long kMaxTag = std::numeric_limits<long long>::max();

/// What the sections of a .msh file contribute, before node tags are mapped to indices.
struct GmshContent {
  std::vector<long long> node_tags;
  std::vector<double> coordinates;       // 3 per node
  std::vector<long long> tet_node_tags;  // 4 per tet
  std::vector<long long> tet_tags;
  bool has_nodes = false;
};

void expect(TextTokenizer& in, std::string_view keyword) {
  const std::string_view token = in.next(keyword);
  if (token != keyword)
    in.fail("expected " + std::string(keyword) + ", got '" + std::string(token.substr(0, 40)) +
            "'");
}

void read_node(TextTokenizer& in, GmshContent& content) {
  content.coordinates.push_back(in.next_double("node x coordinate"));
  content.coordinates.push_back(in.next_double("node y coordinate"));
  content.coordinates.push_back(in.next_double("node z coordinate"));
}

void read_tet_nodes(TextTokenizer& in, long long tag, GmshContent& content) {
  content.tet_tags.push_back(tag);
  for (int k = 0; k < 4; ++k)
    content.tet_node_tags.push_back(in.next_int_in("tet node tag", 1, kMaxTag));
}

void read_nodes_v2(TextTokenizer& in, GmshContent& content) {
  const long long count = in.next_count("node count", 4);
  for (long long i = 0; i < count; ++i) {
    content.node_tags.push_back(in.next_int_in("node tag", 1, kMaxTag));
    read_node(in, content);
  }
}

void read_elements_v2(TextTokenizer& in, GmshContent& content) {
  const long long count = in.next_count("element count", 4);
  for (long long i = 0; i < count; ++i) {
    const long long tag = in.next_int("element tag");
    const long long type = in.next_int("element type");
    const long long num_tags = in.next_int_in("number of element tags", 0, 1000);
    for (long long t = 0; t < num_tags; ++t)
      in.next_int("element tag value");
    if (type == kGmshTet) read_tet_nodes(in, tag, content);
    in.skip_line();
  }
}

void read_nodes_v4(TextTokenizer& in, GmshContent& content) {
  const long long num_blocks = in.next_count("node entity block count", 4);
  const long long num_nodes = in.next_count("node count", 4);
  in.next_int("minimum node tag");
  in.next_int("maximum node tag");
  for (long long b = 0; b < num_blocks; ++b) {
    const long long dim = in.next_int_in("entity dimension", 0, 3);
    in.next_int("entity tag");
    const long long parametric = in.next_int_in("parametric flag", 0, 1);
    const long long count = in.next_count("number of nodes in block", 4);
    const std::size_t first = content.node_tags.size();
    if (first + count > static_cast<std::size_t>(num_nodes))
      in.fail("node blocks hold more than the announced " + std::to_string(num_nodes) + " nodes");
    for (long long i = 0; i < count; ++i)
      content.node_tags.push_back(in.next_int_in("node tag", 1, kMaxTag));
    for (long long i = 0; i < count; ++i) {
      read_node(in, content);
      for (long long p = 0; p < parametric * dim; ++p)
        in.next_double("parametric coordinate");
    }
  }
  if (content.node_tags.size() != static_cast<std::size_t>(num_nodes))
    in.fail("node blocks hold " + std::to_string(content.node_tags.size()) + " nodes, not the " +
            std::to_string(num_nodes) + " announced");
}

void read_elements_v4(TextTokenizer& in, GmshContent& content) {
  const long long num_blocks = in.next_count("element entity block count", 4);
  const long long num_elements = in.next_count("element count", 2);
  in.next_int("minimum element tag");
  in.next_int("maximum element tag");
  long long seen = 0;
  for (long long b = 0; b < num_blocks; ++b) {
    in.next_int_in("entity dimension", 0, 3);
    in.next_int("entity tag");
    const long long type = in.next_int("element type");
    const long long count = in.next_count("number of elements in block", 2);
    seen += count;
    if (seen > num_elements)
      in.fail("element blocks hold more than the announced " + std::to_string(num_elements) +
              " elements");
    for (long long i = 0; i < count; ++i) {
      const long long tag = in.next_int("element tag");
      if (type == kGmshTet) read_tet_nodes(in, tag, content);
      in.skip_line();
    }
  }
  if (seen != num_elements)
    in.fail("element blocks hold " + std::to_string(seen) + " elements, not the " +
            std::to_string(num_elements) + " announced");
}

/// Skips an unknown section ($PhysicalNames, $Entities, $NodeData, ...) up to its $End line.
void skip_section(TextTokenizer& in, std::string_view name) {
  const std::string end = "$End" + std::string(name);
  const int start_line = in.line();
  while (!in.at_end())
    if (in.next(end) == end) return;
  in.fail("section $" + std::string(name) + " opened on line " + std::to_string(start_line) +
          " has no " + end);
}

TetMesh assemble(const GmshContent& content, const std::string& source) {
  if (!content.has_nodes) throw InputError(source + ": no $Nodes section");
  if (content.tet_tags.empty())
    throw InputError(source + ": no tetrahedra (gmsh element type 4) in the file");
  const Index num_vertices = static_cast<Index>(content.node_tags.size());
  if (num_vertices > std::numeric_limits<int>::max()) throw InputError(source + ": too many nodes");

  long long max_tag = 0;
  for (long long tag : content.node_tags)
    max_tag = std::max(max_tag, tag);
  // Tags are usually dense: a lookup table then; a hash map for sparse tags.
  const bool dense = max_tag <= 4 * num_vertices + 1024;
  std::vector<int> table(dense ? max_tag + 1 : 0, -1);
  std::unordered_map<long long, int> map;
  for (Index v = 0; v < num_vertices; ++v) {
    const long long tag = content.node_tags[v];
    const bool inserted = dense ? (table[tag] == -1 ? (table[tag] = int(v), true) : false)
                                : map.emplace(tag, int(v)).second;
    if (!inserted) throw InputError(source + ": node tag " + std::to_string(tag) + " is repeated");
  }

  TetMesh mesh;
  mesh.vertices.resize(num_vertices, 3);
  for (Index v = 0; v < num_vertices; ++v)
    for (int d = 0; d < 3; ++d)
      mesh.vertices(v, d) = content.coordinates[3 * v + d];
  const Index num_tets = static_cast<Index>(content.tet_tags.size());
  mesh.tets.resize(num_tets, 4);
  for (Index t = 0; t < num_tets; ++t) {
    for (int k = 0; k < 4; ++k) {
      const long long tag = content.tet_node_tags[4 * t + k];
      int index = -1;
      if (dense) {
        if (tag <= max_tag) index = table[tag];
      } else if (const auto found = map.find(tag); found != map.end()) {
        index = found->second;
      }
      if (index < 0)
        throw InputError(source + ": tet element " + std::to_string(content.tet_tags[t]) +
                         " references node tag " + std::to_string(tag) + ", which is not defined");
      mesh.tets(t, k) = index;
    }
  }
  return mesh;
}

void write_v2(std::ostream& out, const TetMesh& mesh) {
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << mesh.vertices.rows() << '\n';
  for (Index v = 0; v < mesh.vertices.rows(); ++v)
    write_numbered_point(out, v + 1, mesh.vertices.row(v));
  out << "$EndNodes\n$Elements\n" << mesh.tets.rows() << '\n';
  // Two tags per element: physical group 1, elementary volume 1.
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    out << t + 1 << " 4 2 1 1 " << mesh.tets(t, 0) + 1 << ' ' << mesh.tets(t, 1) + 1 << ' '
        << mesh.tets(t, 2) + 1 << ' ' << mesh.tets(t, 3) + 1 << '\n';
  out << "$EndElements\n";
}

void write_v4(std::ostream& out, const TetMesh& mesh) {
  const Index num_vertices = mesh.vertices.rows();
  const Index num_tets = mesh.tets.rows();
  Vector3d lo = Vector3d::Zero(), hi = Vector3d::Zero();
  if (num_vertices > 0) {
    lo = mesh.vertices.colwise().minCoeff().transpose();
    hi = mesh.vertices.colwise().maxCoeff().transpose();
  }
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  // One volume entity (tag 1) without physical groups or bounding surfaces.
  out << "$Entities\n0 0 0 1\n1";
  for (int d = 0; d < 3; ++d) {
    out << ' ';
    write_double(out, lo[d]);
  }
  for (int d = 0; d < 3; ++d) {
    out << ' ';
    write_double(out, hi[d]);
  }
  out << " 0 0\n$EndEntities\n";
  out << "$Nodes\n1 " << num_vertices << " 1 " << num_vertices << "\n3 1 0 " << num_vertices
      << '\n';
  for (Index v = 0; v < num_vertices; ++v)
    out << v + 1 << '\n';
  for (Index v = 0; v < num_vertices; ++v) {
    for (int d = 0; d < 3; ++d) {
      if (d > 0) out << ' ';
      write_double(out, mesh.vertices(v, d));
    }
    out << '\n';
  }
  out << "$EndNodes\n$Elements\n1 " << num_tets << " 1 " << num_tets << "\n3 1 4 " << num_tets
      << '\n';
  for (Index t = 0; t < num_tets; ++t)
    out << t + 1 << ' ' << mesh.tets(t, 0) + 1 << ' ' << mesh.tets(t, 1) + 1 << ' '
        << mesh.tets(t, 2) + 1 << ' ' << mesh.tets(t, 3) + 1 << '\n';
  out << "$EndElements\n";
}

}  // namespace

TetMesh read_gmsh(const std::filesystem::path& path) {
  TextTokenizer in(path);
  if (in.at_end()) in.fail("empty file");
  expect(in, "$MeshFormat");
  const double version = in.next_double("format version");
  const long long file_type = in.next_int("file type");
  if (file_type != 0) in.fail("binary .msh not supported (save as ASCII)");
  in.next_int("data size");
  const bool v2 = version >= 2.0 && version < 3.0;
  const bool v4 = version == 4.1;
  if (!v2 && !v4)
    in.fail("unsupported .msh version " + std::to_string(version) + " (2.2 and 4.1 are read)");
  expect(in, "$EndMeshFormat");

  GmshContent content;
  while (!in.at_end()) {
    const std::string_view token = in.next("section");
    if (token.empty() || token.front() != '$')
      in.fail("expected a section such as $Nodes, got '" + std::string(token.substr(0, 40)) + "'");
    if (token == "$Nodes") {
      if (content.has_nodes) in.fail("second $Nodes section");
      content.has_nodes = true;
      v2 ? read_nodes_v2(in, content) : read_nodes_v4(in, content);
      expect(in, "$EndNodes");
    } else if (token == "$Elements") {
      v2 ? read_elements_v2(in, content) : read_elements_v4(in, content);
      expect(in, "$EndElements");
    } else {
      skip_section(in, token.substr(1));
    }
  }
  return assemble(content, path.string());
}

void write_gmsh(const std::filesystem::path& path, const TetMesh& mesh, GmshVersion version) {
  write_file_atomically(path, [&](std::ostream& out) {
    version == GmshVersion::v2_2 ? write_v2(out, mesh) : write_v4(out, mesh);
  });
}

}  // namespace strata
