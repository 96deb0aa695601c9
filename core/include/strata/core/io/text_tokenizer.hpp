#pragma once
/// \file text_tokenizer.hpp
/// Whitespace-separated tokens of a text file with line numbers, for the ASCII mesh readers.
/// Every failure is an InputError "<file>:<line>: <what went wrong>"; nothing can loop forever
/// because every call either consumes input or throws.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace strata {

/// The whole content of a file; InputError naming the path if it is missing, a directory or
/// unreadable.
std::string read_file(const std::filesystem::path& path);

class TextTokenizer {
 public:
  /// Reads the whole file. `comment` starts a comment running to the end of the line ('\0': none).
  /// Throws InputError "cannot open '<path>'" when the file cannot be read.
  explicit TextTokenizer(const std::filesystem::path& path, char comment = '\0');
  /// Tokenizes `text`; `source` names it in error messages.
  TextTokenizer(std::string text, std::string source, char comment = '\0');

  /// True when only whitespace and comments remain.
  bool at_end();
  /// The next token without consuming it; empty at the end.
  std::string_view peek();
  /// The next token; `what` names it in the error thrown at the end of the input.
  std::string_view next(std::string_view what);
  /// The next token as an integer (no sign other than '-', no fraction).
  long long next_int(std::string_view what);
  /// The next token as an integer in [lo, hi].
  long long next_int_in(std::string_view what, long long lo, long long hi);
  /// The next token as a double (accepts a leading '+', exponents, "inf", "nan").
  double next_double(std::string_view what);
  /// The next token as a count >= 0 of entries of `tokens_per_entry` tokens each; fails when the
  /// rest of the file is too short to hold them (so a corrupt count cannot allocate gigabytes).
  long long next_count(std::string_view what, int tokens_per_entry);
  /// Drops the rest of the current line (the line of the last token read).
  void skip_line();
  /// The 1-based line of the last token read (or of the current position before any token).
  int line() const { return m_line; }
  /// Bytes not yet consumed; bounds how many entries a count in the file can honestly announce.
  std::size_t remaining_bytes() const { return m_text.size() - m_pos; }
  /// The file name used in messages.
  const std::string& source() const { return m_source; }
  /// Throws InputError "<source>:<line>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  void skip_space();

  std::string m_text;
  std::string m_source;
  char m_comment;
  std::size_t m_pos = 0;
  int m_line = 1;
};

/// Parses a whole token as a double; false if it is not a number.
bool parse_double(std::string_view token, double& value);
/// Parses a whole token as an integer; false if it is not one or overflows.
bool parse_int(std::string_view token, long long& value);

}  // namespace strata
