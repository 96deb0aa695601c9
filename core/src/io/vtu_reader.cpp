#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "strata/core/common/error.hpp"
#include "strata/core/io/text_tokenizer.hpp"
#include "strata/core/io/vtu.hpp"

namespace strata {
namespace {

constexpr int kVtkTetra = 10;

/// A start or end tag of the XML text; attribute values are views into the text.
struct XmlTag {
  std::string_view name;
  std::vector<std::pair<std::string_view, std::string_view>> attributes;
  bool closing = false;
  bool self_closing = false;
  std::size_t end = 0;  ///< offset just past '>'

  std::optional<std::string_view> attribute(std::string_view key) const {
    for (const auto& [k, v] : attributes)
      if (k == key) return v;
    return std::nullopt;
  }
};

/// Just enough XML for VTK files: tags, attributes, comments, processing instructions.
class VtuParser {
 public:
  VtuParser(std::string text, std::string source)
      : m_text(std::move(text)), m_source(std::move(source)) {}

  /// The next tag, or false at the end of the text.
  bool next_tag(XmlTag& tag) {
    while (true) {
      const std::size_t open = m_text.find('<', m_pos);
      if (open == std::string::npos) return false;
      m_pos = open;
      if (m_text.compare(open, 4, "<!--") == 0) {
        m_pos = find_or_fail("-->", open) + 3;
      } else if (m_text.compare(open, 2, "<?") == 0 || m_text.compare(open, 2, "<!") == 0) {
        m_pos = find_or_fail(">", open) + 1;
      } else {
        parse_tag(tag);
        return true;
      }
    }
  }

  /// Text between the last tag and the next '<'.
  std::string_view content() const {
    const std::size_t end = std::min(m_text.find('<', m_pos), m_text.size());
    return std::string_view(m_text).substr(m_pos, end - m_pos);
  }
  std::size_t position() const { return m_pos; }

  [[noreturn]] void fail(const std::string& message, std::size_t offset) const {
    const auto line =
        1 + std::count(m_text.begin(), m_text.begin() + std::min(offset, m_text.size()), '\n');
    throw InputError(m_source + ":" + std::to_string(line) + ": " + message);
  }

 private:
  std::size_t find_or_fail(const char* what, std::size_t from) const {
    const std::size_t found = m_text.find(what, from);
    if (found == std::string::npos) fail("unterminated markup (truncated file?)", from);
    return found;
  }

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  static bool is_name(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' ||
           c == '.';
  }

  void parse_tag(XmlTag& tag) {
    const std::size_t start = m_pos;
    const std::string_view text(m_text);
    tag = XmlTag{};
    std::size_t i = start + 1;
    if (i < text.size() && text[i] == '/') {
      tag.closing = true;
      ++i;
    }
    const std::size_t name_begin = i;
    while (i < text.size() && is_name(text[i]))
      ++i;
    tag.name = text.substr(name_begin, i - name_begin);
    if (tag.name.empty()) fail("malformed tag", start);
    while (true) {
      while (i < text.size() && is_space(text[i]))
        ++i;
      if (i >= text.size())
        fail("unterminated tag <" + std::string(tag.name) + "> (truncated file?)", start);
      if (text[i] == '>') {
        ++i;
        break;
      }
      if (text[i] == '/' && i + 1 < text.size() && text[i + 1] == '>') {
        tag.self_closing = true;
        i += 2;
        break;
      }
      const std::size_t key_begin = i;
      while (i < text.size() && is_name(text[i]))
        ++i;
      const std::string_view key = text.substr(key_begin, i - key_begin);
      while (i < text.size() && is_space(text[i]))
        ++i;
      if (key.empty() || i >= text.size() || text[i] != '=')
        fail("malformed attribute in <" + std::string(tag.name) + ">", start);
      ++i;
      while (i < text.size() && is_space(text[i]))
        ++i;
      if (i >= text.size() || (text[i] != '"' && text[i] != '\''))
        fail("attribute value without quotes in <" + std::string(tag.name) + ">", start);
      const char quote = text[i++];
      const std::size_t value_end = text.find(quote, i);
      if (value_end == std::string_view::npos) fail("unterminated attribute value", start);
      tag.attributes.emplace_back(key, text.substr(i, value_end - i));
      i = value_end + 1;
    }
    tag.end = i;
    m_pos = i;
  }

  std::string m_text;
  std::string m_source;
  std::size_t m_pos = 0;
};

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/// Decodes base64 quantum by quantum, so separately encoded blocks (VTK encodes the header and
/// the data apart, padding included) decode as one byte string. False on invalid input.
bool decode_base64(std::string_view text, std::vector<std::uint8_t>& bytes) {
  char quantum[4];
  int filled = 0;
  for (char c : text) {
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    quantum[filled++] = c;
    if (filled < 4) continue;
    filled = 0;
    int values[4];
    int padding = 0;
    for (int k = 0; k < 4; ++k) {
      if (quantum[k] == '=') {
        if (k < 2) return false;
        values[k] = 0;
        ++padding;
      } else {
        if (padding > 0) return false;
        values[k] = base64_value(quantum[k]);
        if (values[k] < 0) return false;
      }
    }
    const std::uint32_t word = (values[0] << 18) | (values[1] << 12) | (values[2] << 6) | values[3];
    bytes.push_back(static_cast<std::uint8_t>(word >> 16));
    if (padding < 2) bytes.push_back(static_cast<std::uint8_t>(word >> 8));
    if (padding < 1) bytes.push_back(static_cast<std::uint8_t>(word));
  }
  return filled == 0;
}

template <typename T>
void append_values(const std::uint8_t* data, std::size_t count, std::vector<double>& values) {
  for (std::size_t i = 0; i < count; ++i) {
    T value;
    std::memcpy(&value, data + i * sizeof(T), sizeof(T));
    values.push_back(static_cast<double>(value));
  }
}

/// Size in bytes of a VTK scalar type; 0 if unknown.
std::size_t type_size(std::string_view type) {
  if (type == "Float64" || type == "Int64" || type == "UInt64") return 8;
  if (type == "Float32" || type == "Int32" || type == "UInt32") return 4;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int8" || type == "UInt8") return 1;
  return 0;
}

struct FileSettings {
  std::size_t header_size = 4;  // UInt32 unless header_type says UInt64
};

/// The values of a DataArray (ASCII or inline base64) as doubles.
std::vector<double> read_data_array(const VtuParser& parser, const XmlTag& tag,
                                    const FileSettings& settings) {
  const std::string name(tag.attribute("Name").value_or("(unnamed)"));
  const std::string_view type = tag.attribute("type").value_or("");
  const std::string_view format = tag.attribute("format").value_or("ascii");
  if (type_size(type) == 0)
    parser.fail("DataArray '" + name + "' has unknown type '" + std::string(type) + "'", tag.end);
  std::vector<double> values;
  if (tag.self_closing) return values;
  const std::string_view content = parser.content();
  if (format == "ascii") {
    TextTokenizer tokens(std::string(content), "", '\0');
    while (!tokens.at_end()) {
      const std::string_view token = tokens.next("value");
      double value = 0.0;
      if (!parse_double(token, value))
        parser.fail(
            "DataArray '" + name + "': '" + std::string(token.substr(0, 40)) + "' is not a number",
            tag.end + (token.data() - content.data()));
      values.push_back(value);
    }
    return values;
  }
  if (format != "binary")
    parser.fail("DataArray '" + name + "' has format '" + std::string(format) +
                    "' (appended data is not supported; save as ascii or inline binary)",
                tag.end);
  std::vector<std::uint8_t> bytes;
  if (!decode_base64(content, bytes))
    parser.fail("DataArray '" + name + "': invalid base64 data", tag.end);
  if (bytes.size() < settings.header_size)
    parser.fail("DataArray '" + name + "': binary data shorter than its header", tag.end);
  std::uint64_t num_bytes = 0;
  if (settings.header_size == 8) {
    std::memcpy(&num_bytes, bytes.data(), 8);
  } else {
    std::uint32_t header32 = 0;
    std::memcpy(&header32, bytes.data(), 4);
    num_bytes = header32;
  }
  if (num_bytes > bytes.size() - settings.header_size || num_bytes % type_size(type) != 0)
    parser.fail("DataArray '" + name + "': binary header announces " + std::to_string(num_bytes) +
                    " bytes, which the data does not hold",
                tag.end);
  const std::uint8_t* data = bytes.data() + settings.header_size;
  const std::size_t count = num_bytes / type_size(type);
  values.reserve(count);
  if (type == "Float64")
    append_values<double>(data, count, values);
  else if (type == "Float32")
    append_values<float>(data, count, values);
  else if (type == "Int64")
    append_values<std::int64_t>(data, count, values);
  else if (type == "UInt64")
    append_values<std::uint64_t>(data, count, values);
  else if (type == "Int32")
    append_values<std::int32_t>(data, count, values);
  else if (type == "UInt32")
    append_values<std::uint32_t>(data, count, values);
  else if (type == "Int16")
    append_values<std::int16_t>(data, count, values);
  else if (type == "UInt16")
    append_values<std::uint16_t>(data, count, values);
  else if (type == "Int8")
    append_values<std::int8_t>(data, count, values);
  else
    append_values<std::uint8_t>(data, count, values);
  return values;
}

long long parse_count(const VtuParser& parser, const XmlTag& tag, std::string_view key) {
  long long value = -1;
  const std::optional<std::string_view> text = tag.attribute(key);
  if (!text || !parse_int(*text, value) || value < 0 || value > std::numeric_limits<int>::max())
    parser.fail("<Piece> needs a valid " + std::string(key), tag.end);
  return value;
}

/// An array of integer-valued doubles as indices; fails on fractions or out-of-range values.
bool is_index(double value, double limit) {
  return value >= 0 && value < limit && value == static_cast<double>(static_cast<long long>(value));
}

}  // namespace

TetMesh read_vtu(const std::filesystem::path& path) {
  const std::string source = path.string();
  VtuParser parser(read_file(path), source);
  enum class Section { none, points, cells, other };
  Section section = Section::none;
  FileSettings settings;
  bool seen_file = false, seen_piece = false;
  long long num_points = 0, num_cells = 0;
  std::vector<double> points, connectivity, offsets, types;
  bool has_points = false, has_connectivity = false, has_offsets = false, has_types = false;

  XmlTag tag;
  while (parser.next_tag(tag)) {
    if (tag.closing) {
      if (tag.name == "Points" || tag.name == "Cells" || tag.name == "PointData" ||
          tag.name == "CellData" || tag.name == "FieldData")
        section = Section::none;
      continue;
    }
    if (tag.name == "VTKFile") {
      seen_file = true;
      if (tag.attribute("type").value_or("") != "UnstructuredGrid")
        parser.fail("not an UnstructuredGrid VTK file", tag.end);
      if (tag.attribute("byte_order").value_or("LittleEndian") != "LittleEndian")
        parser.fail("big-endian data is not supported", tag.end);
      if (tag.attribute("compressor"))
        parser.fail("compressed .vtu is not supported (save uncompressed)", tag.end);
      if (tag.attribute("header_type").value_or("UInt32") == "UInt64") settings.header_size = 8;
    } else if (tag.name == "Piece") {
      if (seen_piece) parser.fail("more than one <Piece> is not supported", tag.end);
      seen_piece = true;
      num_points = parse_count(parser, tag, "NumberOfPoints");
      num_cells = parse_count(parser, tag, "NumberOfCells");
    } else if (tag.name == "AppendedData") {
      parser.fail("appended data is not supported (save as ascii or inline binary)", tag.end);
    } else if (!tag.self_closing && tag.name == "Points") {
      section = Section::points;
    } else if (!tag.self_closing && tag.name == "Cells") {
      section = Section::cells;
    } else if (!tag.self_closing &&
               (tag.name == "PointData" || tag.name == "CellData" || tag.name == "FieldData")) {
      section = Section::other;
    } else if (tag.name == "DataArray" && section == Section::points && !has_points) {
      points = read_data_array(parser, tag, settings);
      has_points = true;
    } else if (tag.name == "DataArray" && section == Section::cells) {
      const std::string_view name = tag.attribute("Name").value_or("");
      if (name == "connectivity") {
        connectivity = read_data_array(parser, tag, settings);
        has_connectivity = true;
      } else if (name == "offsets") {
        offsets = read_data_array(parser, tag, settings);
        has_offsets = true;
      } else if (name == "types") {
        types = read_data_array(parser, tag, settings);
        has_types = true;
      }
    }
  }
  if (!seen_file) throw InputError(source + ": not a VTK XML file (no <VTKFile>)");
  if (!seen_piece) throw InputError(source + ": no <Piece> (truncated file?)");
  if (!has_points || !has_connectivity || !has_offsets || !has_types)
    throw InputError(source + ": missing Points or Cells arrays (connectivity, offsets, types)");
  if (points.size() != 3 * static_cast<std::size_t>(num_points))
    throw InputError(source + ": Points holds " + std::to_string(points.size()) +
                     " values, expected 3 × NumberOfPoints = " + std::to_string(3 * num_points));
  if (offsets.size() != static_cast<std::size_t>(num_cells) ||
      types.size() != static_cast<std::size_t>(num_cells))
    throw InputError(source + ": offsets/types hold " + std::to_string(offsets.size()) + "/" +
                     std::to_string(types.size()) +
                     " values, expected NumberOfCells = " + std::to_string(num_cells));

  TetMesh mesh;
  mesh.vertices.resize(num_points, 3);
  for (long long v = 0; v < num_points; ++v)
    for (int d = 0; d < 3; ++d)
      mesh.vertices(v, d) = points[3 * v + d];
  std::vector<int> tets;
  const double connectivity_size = static_cast<double>(connectivity.size());
  double begin = 0;
  for (long long c = 0; c < num_cells; ++c) {
    const double end = offsets[c];
    if (!is_index(end, connectivity_size + 1) || end < begin)
      throw InputError(source + ": cell " + std::to_string(c) + " has invalid offset " +
                       std::to_string(end));
    if (types[c] == kVtkTetra) {
      if (end - begin != 4)
        throw InputError(source + ": tetra cell " + std::to_string(c) + " has " +
                         std::to_string(static_cast<long long>(end - begin)) + " points, not 4");
      for (long long k = static_cast<long long>(begin); k < static_cast<long long>(end); ++k) {
        if (!is_index(connectivity[k], static_cast<double>(num_points)))
          throw InputError(source + ": cell " + std::to_string(c) + " references point " +
                           std::to_string(connectivity[k]) + " of " + std::to_string(num_points));
        tets.push_back(static_cast<int>(connectivity[k]));
      }
    }
    begin = end;
  }
  if (tets.empty()) throw InputError(source + ": no tetrahedra (VTK cell type 10) in the file");
  mesh.tets.resize(static_cast<Index>(tets.size() / 4), 4);
  for (Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      mesh.tets(t, k) = tets[4 * t + k];
  return mesh;
}

}  // namespace strata
