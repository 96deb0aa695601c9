#include "vtk_xml.hpp"

#include <libdeflate.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <memory>
#include <type_traits>

#include "strata/core/common/error.hpp"
#include "strata/core/io/number_text.hpp"

namespace strata::vtk_xml {
namespace {

template <typename Matrix>
void check_rows(const std::filesystem::path& path, const std::string& kind, const std::string& name,
                const Matrix& values, Index rows) {
  if (values.rows() != rows || values.cols() < 1)
    throw InputError("cannot write '" + path.string() + "': " + kind + " field '" + name +
                     "' has " + std::to_string(values.rows()) + " × " +
                     std::to_string(values.cols()) + " entries, expected " + std::to_string(rows) +
                     " rows");
}

}  // namespace

std::string escape(const std::string& text) {
  std::string result;
  result.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        result += "&amp;";
        break;
      case '<':
        result += "&lt;";
        break;
      case '>':
        result += "&gt;";
        break;
      case '"':
        result += "&quot;";
        break;
      default:
        result += c;
    }
  }
  return result;
}

void check_field_rows(const std::filesystem::path& path, const VtuFields& fields, Index num_points,
                      Index num_cells) {
  for (const auto& [name, values] : fields.point_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.point_int_data)
    check_rows(path, "point", name, values, num_points);
  for (const auto& [name, values] : fields.cell_data)
    check_rows(path, "cell", name, values, num_cells);
  for (const auto& [name, values] : fields.cell_int_data)
    check_rows(path, "cell", name, values, num_cells);
}

namespace {

constexpr std::size_t kBlockSize = 1 << 16;  ///< uncompressed bytes per zlib block
/// An array whose first block deflates to more than this share of its size is stored.
constexpr double kStoreRatio = 0.8;

template <typename T>
const char* type_name() {
  if constexpr (std::is_same_v<T, double>)
    return "Float64";
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return "Int32";
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return "Int64";
  else {
    static_assert(std::is_same_v<T, std::uint8_t>, "unsupported DataArray type");
    return "UInt8";
  }
}

/// This thread's libdeflate compressor at `level` (1: fastest deflate, 0: stored blocks); a
/// compressor serves one thread at a time.
libdeflate_compressor& thread_compressor(int level) {
  struct Free {
    void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
  };
  thread_local std::unique_ptr<libdeflate_compressor, Free> compressors[2];
  std::unique_ptr<libdeflate_compressor, Free>& compressor = compressors[level];
  if (!compressor) {
    compressor.reset(libdeflate_alloc_compressor(level));
    if (!compressor) throw std::bad_alloc();
  }
  return *compressor;
}

void put_u64(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint64_t value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);  // little endian, as byte_order says
}

/// The rows of a field matrix, row by row (in parallel over rows).
template <typename Scalar, typename Matrix>
std::vector<Scalar> row_major(const Matrix& values) {
  const Index rows = values.rows(), cols = values.cols();
  std::vector<Scalar> flat(static_cast<std::size_t>(rows * cols));
  tbb::parallel_for(tbb::blocked_range<Index>(0, rows, 4096),
                    [&](const tbb::blocked_range<Index>& range) {
                      for (Index r = range.begin(); r != range.end(); ++r)
                        for (Index c = 0; c < cols; ++c)
                          flat[r * cols + c] = static_cast<Scalar>(values(r, c));
                    });
  return flat;
}

}  // namespace

void DataArrayWriter::begin_file(std::ostream& out, const char* type) const {
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"" << type
      << "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\""
      << (m_encoding == VtkEncoding::binary ? " compressor=\"vtkZLibDataCompressor\"" : "")
      << ">\n";
}

void DataArrayWriter::append_compressed(const std::uint8_t* data, std::size_t size,
                                        std::vector<std::uint8_t>& into) {
  const std::size_t num_blocks = (size + kBlockSize - 1) / kBlockSize;
  std::vector<std::vector<std::uint8_t>> compressed(num_blocks);
  std::atomic<bool> failed{false};
  const auto compress_block = [&](std::size_t b, int level) {
    const std::size_t begin = b * kBlockSize;
    const std::size_t length = std::min(kBlockSize, size - begin);
    std::vector<std::uint8_t>& block = compressed[b];
    libdeflate_compressor& compressor = thread_compressor(level);
    block.resize(libdeflate_zlib_compress_bound(&compressor, length));
    const std::size_t written =
        libdeflate_zlib_compress(&compressor, data + begin, length, block.data(), block.size());
    if (written == 0) failed = true;
    block.resize(written);
  };
  // The first block decides the level of the others: an array whose first block deflates to
  // more than kStoreRatio of its size (a field of doubles that vary from tet to tet, such as the
  // stress) is stored in zlib's uncompressed blocks, still a zlib stream to every reader. Storing
  // costs a copy and a checksum; deflating doubles that vary costs about 10 ns a byte (libdeflate,
  // level 1) to save a few per cent.
  if (num_blocks > 0) compress_block(0, 1);
  const double first_length = static_cast<double>(std::min(kBlockSize, size));
  const int level =
      num_blocks > 0 && static_cast<double>(compressed[0].size()) > kStoreRatio * first_length ? 0
                                                                                               : 1;
  // The other blocks are compressed independently (in parallel, each into a buffer of its own)
  // and appended in order: the bytes do not depend on the thread count.
  tbb::parallel_for(std::size_t(1), std::max<std::size_t>(num_blocks, 1),
                    [&](std::size_t b) { compress_block(b, level); });
  if (failed) throw std::runtime_error("libdeflate could not compress a VTK data block");
  std::size_t total = 8 * (3 + num_blocks);
  for (const std::vector<std::uint8_t>& block : compressed)
    total += block.size();
  const std::size_t header_at = into.size();
  into.resize(header_at + total);
  put_u64(into, header_at, num_blocks);
  put_u64(into, header_at + 8, kBlockSize);
  put_u64(into, header_at + 16, size % kBlockSize);  // 0: the last block is full
  std::size_t at = header_at + 8 * (3 + num_blocks);
  for (std::size_t b = 0; b < num_blocks; ++b) {
    put_u64(into, header_at + 8 * (3 + b), compressed[b].size());
    std::memcpy(into.data() + at, compressed[b].data(), compressed[b].size());
    at += compressed[b].size();
  }
}

template <typename T>
void DataArrayWriter::write(std::ostream& out, const std::string& name, int components,
                            const std::vector<T>& values) {
  out << "        <DataArray type=\"" << type_name<T>() << "\"";
  if (!name.empty()) out << " Name=\"" << escape(name) << "\"";
  out << " NumberOfComponents=\"" << components << "\"";
  if (m_encoding == VtkEncoding::binary) {
    out << " format=\"appended\" offset=\"" << m_appended.size() << "\"/>\n";
    const auto* raw = reinterpret_cast<const std::uint8_t*>(values.data());
    const std::size_t size = values.size() * sizeof(T);
    if (!std::is_integral_v<T> || m_cache == nullptr) {
      append_compressed(raw, size, m_appended);
      return;
    }
    const std::string key = name + "/" + type_name<T>() + "/" + std::to_string(components);
    if (const std::vector<std::uint8_t>* kept = m_cache->find(key, raw, size)) {
      m_appended.insert(m_appended.end(), kept->begin(), kept->end());
      return;
    }
    std::vector<std::uint8_t> made;
    append_compressed(raw, size, made);
    m_appended.insert(m_appended.end(), made.begin(), made.end());
    m_cache->keep(key, raw, size, std::move(made));
    return;
  }
  out << " format=\"ascii\">\n";
  const std::size_t per_line = components > 1 ? static_cast<std::size_t>(components) : 16;
  for (std::size_t i = 0; i < values.size(); ++i) {
    out << (i % per_line == 0 ? "          " : " ");
    if constexpr (std::is_same_v<T, double>)
      write_double(out, values[i]);
    else
      out << static_cast<long long>(values[i]);
    if (i % per_line == per_line - 1 || i + 1 == values.size()) out << '\n';
  }
  out << "        </DataArray>\n";
}

template void DataArrayWriter::write(std::ostream&, const std::string&, int,
                                     const std::vector<double>&);
template void DataArrayWriter::write(std::ostream&, const std::string&, int,
                                     const std::vector<std::int32_t>&);
template void DataArrayWriter::write(std::ostream&, const std::string&, int,
                                     const std::vector<std::int64_t>&);
template void DataArrayWriter::write(std::ostream&, const std::string&, int,
                                     const std::vector<std::uint8_t>&);

void DataArrayWriter::write_fields_and_points(std::ostream& out, const VtuFields& fields,
                                              ConstRef<MatrixX3d> positions) {
  if (!fields.point_data.empty() || !fields.point_int_data.empty()) {
    out << "      <PointData>\n";
    for (const auto& [name, values] : fields.point_data)
      write(out, name, static_cast<int>(values.cols()), row_major<double>(values));
    for (const auto& [name, values] : fields.point_int_data)
      write(out, name, static_cast<int>(values.cols()), row_major<std::int32_t>(values));
    out << "      </PointData>\n";
  }
  if (!fields.cell_data.empty() || !fields.cell_int_data.empty()) {
    out << "      <CellData>\n";
    for (const auto& [name, values] : fields.cell_data)
      write(out, name, static_cast<int>(values.cols()), row_major<double>(values));
    for (const auto& [name, values] : fields.cell_int_data)
      write(out, name, static_cast<int>(values.cols()), row_major<std::int32_t>(values));
    out << "      </CellData>\n";
  }
  out << "      <Points>\n";
  write(out, "", 3, row_major<double>(positions));
  out << "      </Points>\n";
}

void DataArrayWriter::end_file(std::ostream& out) const {
  if (m_encoding == VtkEncoding::binary) {
    out << "  <AppendedData encoding=\"raw\">\n   _";
    out.write(reinterpret_cast<const char*>(m_appended.data()),
              static_cast<std::streamsize>(m_appended.size()));
    out << "\n  </AppendedData>\n";
  }
  out << "</VTKFile>\n";
}

}  // namespace strata::vtk_xml

namespace strata {

const std::vector<std::uint8_t>* VtuArrayCache::find(const std::string& name,
                                                     const std::uint8_t* raw, std::size_t size) {
  const auto found = m_entries.find(name);
  if (found == m_entries.end() || found->second.raw.size() != size ||
      (size > 0 && std::memcmp(found->second.raw.data(), raw, size) != 0))
    return nullptr;
  ++m_reused;
  return &found->second.compressed;
}

void VtuArrayCache::keep(const std::string& name, const std::uint8_t* raw, std::size_t size,
                         std::vector<std::uint8_t> compressed) {
  Entry entry{std::vector<std::uint8_t>(raw, raw + size), std::move(compressed)};
  m_entries.insert_or_assign(name, std::move(entry));  // nothing is kept if a copy fails
  ++m_compressed;
}

}  // namespace strata
