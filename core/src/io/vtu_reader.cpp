#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <deque>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <zlib.h>

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
  const std::string& text() const { return m_text; }

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
  bool compressed = false;      // compressor="vtkZLibDataCompressor"
};

/// A header word (UInt32 or UInt64) at `data`.
std::uint64_t header_word(const std::uint8_t* data, std::size_t header_size) {
  if (header_size == 8) {
    std::uint64_t word = 0;
    std::memcpy(&word, data, 8);
    return word;
  }
  std::uint32_t word = 0;
  std::memcpy(&word, data, 4);
  return word;
}

/// The payload of one binary DataArray whose encoded form (header, then data) starts at `data`
/// with `available` bytes: the uncompressed bytes, or the zlib blocks inflated. Empty with
/// `error` set on a truncated or corrupt array.
std::vector<std::uint8_t> decode_payload(const std::uint8_t* data, std::size_t available,
                                         const FileSettings& settings, std::string& error) {
  const std::size_t h = settings.header_size;
  std::vector<std::uint8_t> payload;
  if (available < h) {
    error = "binary data shorter than its header";
    return payload;
  }
  if (!settings.compressed) {
    const std::uint64_t num_bytes = header_word(data, h);
    if (num_bytes > available - h) {
      error = "binary header announces " + std::to_string(num_bytes) +
              " bytes, which the data does not hold";
      return payload;
    }
    payload.assign(data + h, data + h + num_bytes);
    return payload;
  }
  if (available < 3 * h) {
    error = "compressed data shorter than its header";
    return payload;
  }
  const std::uint64_t num_blocks = header_word(data, h);
  const std::uint64_t block_size = header_word(data + h, h);
  const std::uint64_t last_size = header_word(data + 2 * h, h);
  if (num_blocks > (available - 3 * h) / h || last_size > block_size) {
    error = "compressed header announces " + std::to_string(num_blocks) +
            " blocks, which the data does not hold";
    return payload;
  }
  std::size_t at = (3 + num_blocks) * h;
  for (std::uint64_t b = 0; b < num_blocks; ++b) {
    const std::uint64_t compressed = header_word(data + (3 + b) * h, h);
    const std::uint64_t expected = b + 1 == num_blocks && last_size != 0 ? last_size : block_size;
    if (compressed > available - at) {
      error = "compressed block " + std::to_string(b) + " is truncated";
      return {};
    }
    const std::size_t begin = payload.size();
    payload.resize(begin + expected);
    uLongf inflated = static_cast<uLongf>(expected);
    if (uncompress(payload.data() + begin, &inflated, data + at, static_cast<uLong>(compressed)) !=
            Z_OK ||
        inflated != expected) {
      error = "compressed block " + std::to_string(b) + " does not inflate (corrupt data?)";
      return {};
    }
    at += compressed;
  }
  return payload;
}

/// The values of a binary payload of VTK `type` as doubles.
std::vector<double> payload_values(std::string_view type, const std::vector<std::uint8_t>& bytes) {
  std::vector<double> values;
  const std::size_t count = bytes.size() / type_size(type);
  values.reserve(count);
  const std::uint8_t* data = bytes.data();
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

/// A DataArray whose values are in the <AppendedData> block, read once the block is found.
struct AppendedArray {
  std::vector<double>* values;
  std::string name;
  std::string type;
  std::uint64_t offset;
  std::size_t tag_end;
};

/// The values of a DataArray (ASCII or inline base64) as doubles; an appended one is queued in
/// `appended` and read at the end.
void read_data_array(const VtuParser& parser, const XmlTag& tag, const FileSettings& settings,
                     std::vector<double>& values, std::vector<AppendedArray>& appended) {
  const std::string name(tag.attribute("Name").value_or("(unnamed)"));
  const std::string_view type = tag.attribute("type").value_or("");
  const std::string_view format = tag.attribute("format").value_or("ascii");
  if (type_size(type) == 0)
    parser.fail("DataArray '" + name + "' has unknown type '" + std::string(type) + "'", tag.end);
  values.clear();
  if (format == "appended") {
    long long offset = -1;
    const std::optional<std::string_view> text = tag.attribute("offset");
    if (!text || !parse_int(*text, offset) || offset < 0)
      parser.fail("appended DataArray '" + name + "' needs a valid offset", tag.end);
    appended.push_back(
        {&values, name, std::string(type), static_cast<std::uint64_t>(offset), tag.end});
    return;
  }
  if (tag.self_closing) return;
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
    return;
  }
  if (format != "binary")
    parser.fail("DataArray '" + name + "' has unknown format '" + std::string(format) + "'",
                tag.end);
  std::vector<std::uint8_t> bytes;
  if (!decode_base64(content, bytes))
    parser.fail("DataArray '" + name + "': invalid base64 data", tag.end);
  std::string error;
  const std::vector<std::uint8_t> payload =
      decode_payload(bytes.data(), bytes.size(), settings, error);
  if (!error.empty()) parser.fail("DataArray '" + name + "': " + error, tag.end);
  if (payload.size() % type_size(type) != 0)
    parser.fail("DataArray '" + name + "': " + std::to_string(payload.size()) +
                    " bytes are not whole " + std::string(type) + " values",
                tag.end);
  values = payload_values(type, payload);
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

/// One DataArray as read: its section, name, components and values.
struct RawArray {
  std::string section;  ///< "Points", "PointData", "CellData", "Cells", "Polys", "Lines", …
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// Everything of a single-piece VTK XML file that strata reads.
struct RawFile {
  std::string type;
  long long num_points = 0;
  long long num_cells = 0;      ///< NumberOfCells, or the sum of a PolyData piece's cell counts
  std::deque<RawArray> arrays;  // a deque: queued appended arrays keep their addresses

  const RawArray* find(std::string_view section, std::string_view name) const {
    for (const RawArray& array : arrays)
      if (array.section == section && (name.empty() || array.name == name)) return &array;
    return nullptr;
  }
};

bool is_cell_section(std::string_view name) {
  return name == "Cells" || name == "Polys" || name == "Lines" || name == "Verts" ||
         name == "Strips";
}

/// Parses `path`, which must be a VTK XML file of one of `types`.
RawFile parse_vtk_file(const std::filesystem::path& path,
                       std::initializer_list<std::string_view> types) {
  const std::string source = path.string();
  VtuParser parser(read_file(path), source);
  FileSettings settings;
  RawFile file;
  bool seen_file = false, seen_piece = false;
  std::string section;
  std::vector<AppendedArray> appended;
  std::size_t appended_start = std::string::npos;

  XmlTag tag;
  while (parser.next_tag(tag)) {
    if (tag.closing) {
      if (tag.name == section) section.clear();
      continue;
    }
    if (tag.name == "VTKFile") {
      seen_file = true;
      const std::string_view type = tag.attribute("type").value_or("");
      if (std::find(types.begin(), types.end(), type) == types.end()) {
        std::string expected;
        for (std::string_view t : types)
          expected += (expected.empty() ? "" : " or ") + std::string(t);
        parser.fail("not an " + expected + " VTK file", tag.end);
      }
      file.type = type;
      if (tag.attribute("byte_order").value_or("LittleEndian") != "LittleEndian")
        parser.fail("big-endian data is not supported", tag.end);
      if (const auto compressor = tag.attribute("compressor")) {
        if (*compressor != "vtkZLibDataCompressor")
          parser.fail("compressor '" + std::string(*compressor) +
                          "' is not supported (save uncompressed or with zlib)",
                      tag.end);
        settings.compressed = true;
      }
      if (tag.attribute("header_type").value_or("UInt32") == "UInt64") settings.header_size = 8;
    } else if (tag.name == "Piece") {
      if (seen_piece) parser.fail("more than one <Piece> is not supported", tag.end);
      seen_piece = true;
      file.num_points = parse_count(parser, tag, "NumberOfPoints");
      if (file.type == "PolyData") {
        for (const char* key :
             {"NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys"})
          if (tag.attribute(key)) file.num_cells += parse_count(parser, tag, key);
      } else {
        file.num_cells = parse_count(parser, tag, "NumberOfCells");
      }
    } else if (tag.name == "AppendedData") {
      // Raw bytes follow up to the end of the file; no markup is parsed past this tag.
      if (tag.attribute("encoding").value_or("raw") != "raw")
        parser.fail("appended data in encoding '" +
                        std::string(tag.attribute("encoding").value_or("")) +
                        "' is not supported (save raw, inline binary or ascii)",
                    tag.end);
      const std::size_t underscore = parser.text().find('_', tag.end);
      if (underscore == std::string::npos)
        parser.fail("<AppendedData> without its '_' marker (truncated file?)", tag.end);
      appended_start = underscore + 1;
      break;
    } else if (tag.name == "DataArray") {
      if (section.empty() || section == "FieldData") continue;
      if (section == "Points" && file.find("Points", "")) continue;
      RawArray& array = file.arrays.emplace_back();
      array.section = section;
      array.name = tag.attribute("Name").value_or("");
      long long components = 1;
      if (const auto text = tag.attribute("NumberOfComponents"))
        if (!parse_int(*text, components) || components < 1 || components > 1024)
          parser.fail("DataArray '" + array.name + "' has an invalid NumberOfComponents", tag.end);
      array.components = static_cast<int>(components);
      read_data_array(parser, tag, settings, array.values, appended);
    } else if (!tag.self_closing &&
               (tag.name == "Points" || tag.name == "PointData" || tag.name == "CellData" ||
                tag.name == "FieldData" || is_cell_section(tag.name))) {
      section = tag.name;
    }
  }
  if (!seen_file) throw InputError(source + ": not a VTK XML file (no <VTKFile>)");
  if (!appended.empty() && appended_start == std::string::npos)
    throw InputError(source + ": DataArray '" + appended.front().name +
                     "' is appended but the file has no <AppendedData> (truncated file?)");
  for (const AppendedArray& array : appended) {
    const std::string& text = parser.text();
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(text.data());
    const std::size_t available = text.size() - appended_start;
    if (array.offset > available)
      parser.fail("appended DataArray '" + array.name + "' starts past the end of the file",
                  array.tag_end);
    std::string error;
    const std::vector<std::uint8_t> payload = decode_payload(
        bytes + appended_start + array.offset, available - array.offset, settings, error);
    if (!error.empty())
      parser.fail("appended DataArray '" + array.name + "': " + error, array.tag_end);
    if (payload.size() % type_size(array.type) != 0)
      parser.fail("appended DataArray '" + array.name + "': " + std::to_string(payload.size()) +
                      " bytes are not whole " + array.type + " values",
                  array.tag_end);
    *array.values = payload_values(array.type, payload);
  }
  if (!seen_piece) throw InputError(source + ": no <Piece> (truncated file?)");
  return file;
}

/// `array`'s values as rows × components; throws InputError unless there are `rows` tuples.
Eigen::MatrixXd as_matrix(const std::string& source, const RawArray& array, long long rows) {
  if (array.values.size() != static_cast<std::size_t>(rows) * array.components)
    throw InputError(source + ": " + array.section + " array '" + array.name + "' holds " +
                     std::to_string(array.values.size()) + " values, expected " +
                     std::to_string(rows) + " × " + std::to_string(array.components));
  Eigen::MatrixXd matrix(rows, array.components);
  for (long long r = 0; r < rows; ++r)
    for (int c = 0; c < array.components; ++c)
      matrix(r, c) = array.values[r * array.components + c];
  return matrix;
}

}  // namespace

const Eigen::MatrixXd& VtkFrame::point_field(const std::string& name) const {
  for (const auto& [key, values] : point_data)
    if (key == name) return values;
  throw InputError("VTK frame has no point field '" + name + "'");
}

const Eigen::MatrixXd& VtkFrame::cell_field(const std::string& name) const {
  for (const auto& [key, values] : cell_data)
    if (key == name) return values;
  throw InputError("VTK frame has no cell field '" + name + "'");
}

VtkFrame read_vtk_frame(const std::filesystem::path& path) {
  const std::string source = path.string();
  const RawFile file = parse_vtk_file(path, {"UnstructuredGrid", "PolyData"});
  VtkFrame frame;
  frame.type = file.type;
  const RawArray* points = file.find("Points", "");
  if (!points) throw InputError(source + ": no Points array");
  frame.points = as_matrix(source, *points, file.num_points);
  for (const RawArray& array : file.arrays) {
    if (array.section == "PointData")
      frame.point_data.emplace_back(array.name, as_matrix(source, array, file.num_points));
    else if (array.section == "CellData")
      frame.cell_data.emplace_back(array.name, as_matrix(source, array, file.num_cells));
    else if (is_cell_section(array.section))
      frame.cells.emplace_back(array.section + "/" + array.name, array.values);
  }
  return frame;
}

TetMesh read_vtu(const std::filesystem::path& path) {
  const std::string source = path.string();
  const RawFile file = parse_vtk_file(path, {"UnstructuredGrid"});
  const long long num_points = file.num_points, num_cells = file.num_cells;
  const RawArray* points_array = file.find("Points", "");
  const RawArray* connectivity_array = file.find("Cells", "connectivity");
  const RawArray* offsets_array = file.find("Cells", "offsets");
  const RawArray* types_array = file.find("Cells", "types");
  if (!points_array || !connectivity_array || !offsets_array || !types_array)
    throw InputError(source + ": missing Points or Cells arrays (connectivity, offsets, types)");
  const std::vector<double>& points = points_array->values;
  const std::vector<double>& connectivity = connectivity_array->values;
  const std::vector<double>& offsets = offsets_array->values;
  const std::vector<double>& types = types_array->values;
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
