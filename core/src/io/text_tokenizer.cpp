#include "strata/core/io/text_tokenizer.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  std::string shown(token.substr(0, kMaxShown));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  if (token.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

}  // namespace

std::string read_file(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw InputError("cannot open '" + path.string() + "': it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path.string() + "'");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw InputError("cannot read '" + path.string() + "'");
  return std::move(content).str();
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return !token.empty() && error == std::errc() && end == token.data() + token.size();
}

bool parse_int(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return !token.empty() && error == std::errc() && end == token.data() + token.size();
}

TextTokenizer::TextTokenizer(const std::filesystem::path& path, char comment)
    : TextTokenizer(read_file(path), path.string(), comment) {}

TextTokenizer::TextTokenizer(std::string text, std::string source, char comment)
    : m_text(std::move(text)), m_source(std::move(source)), m_comment(comment) {}

void TextTokenizer::skip_space() {
  while (m_pos < m_text.size()) {
    const char c = m_text[m_pos];
    if (c == '\n') {
      ++m_line;
      ++m_pos;
    } else if (is_space(c)) {
      ++m_pos;
    } else if (m_comment != '\0' && c == m_comment) {
      while (m_pos < m_text.size() && m_text[m_pos] != '\n')
        ++m_pos;
    } else {
      return;
    }
  }
}

bool TextTokenizer::at_end() {
  skip_space();
  return m_pos >= m_text.size();
}

std::string_view TextTokenizer::peek() {
  skip_space();
  std::size_t end = m_pos;
  while (end < m_text.size() && !is_space(m_text[end]) &&
         !(m_comment != '\0' && m_text[end] == m_comment))
    ++end;
  return std::string_view(m_text).substr(m_pos, end - m_pos);
}

std::string_view TextTokenizer::next(std::string_view what) {
  const std::string_view token = peek();
  if (token.empty()) fail("unexpected end of file while reading " + std::string(what));
  m_pos += token.size();
  return token;
}

long long TextTokenizer::next_int(std::string_view what) {
  const std::string_view token = next(what);
  long long value = 0;
  if (!parse_int(token, value))
    fail("expected an integer " + std::string(what) + ", got " + quoted(token));
  return value;
}

long long TextTokenizer::next_int_in(std::string_view what, long long lo, long long hi) {
  const long long value = next_int(what);
  if (value < lo || value > hi)
    fail(std::string(what) + " " + std::to_string(value) + " out of range [" + std::to_string(lo) +
         ", " + std::to_string(hi) + "]");
  return value;
}

double TextTokenizer::next_double(std::string_view what) {
  const std::string_view token = next(what);
  double value = 0.0;
  if (!parse_double(token, value))
    fail("expected a number for " + std::string(what) + ", got " + quoted(token));
  return value;
}

long long TextTokenizer::next_count(std::string_view what, int tokens_per_entry) {
  const long long count = next_int(what);
  if (count < 0) fail(std::string(what) + " " + std::to_string(count) + " is negative");
  // Every token takes at least two bytes (a character and a separator).
  const std::size_t bytes_per_entry = 2 * static_cast<std::size_t>(std::max(tokens_per_entry, 1));
  if (static_cast<unsigned long long>(count) > remaining_bytes() / bytes_per_entry + 1)
    fail(std::string(what) + " " + std::to_string(count) +
         " is larger than the rest of the file can hold (truncated file?)");
  return count;
}

void TextTokenizer::skip_line() {
  while (m_pos < m_text.size() && m_text[m_pos] != '\n')
    ++m_pos;
}

void TextTokenizer::fail(const std::string& message) const {
  throw InputError(m_source + ":" + std::to_string(m_line) + ": " + message);
}

}  // namespace strata
