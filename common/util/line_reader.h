// LineReader: reads a text file line by line for the parsers of mesh and surface files,
// so that every error they raise starts with "file:line:" (1-based) and quotes what it found.
//
// A line's trailing '\r' (files saved on Windows) is dropped; tokens are its fields
// separated by blanks or tabs. Numbers must be whole tokens in C locale ("1.5", "-2e-3";
// a leading '+' is accepted); integers must fit std::int64_t; reals must be finite.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

namespace cohaptic {

/// Opens a file for a parser. Throws Error naming the path and the system's reason
/// ("No such file or directory", "Permission denied", "Is a directory").
std::ifstream open_text_file(const std::filesystem::path& path);

class LineReader {
 public:
  LineReader(std::istream& in, std::string source_name);

  /// Advances to the next line; false at the end of the input. Throws Error if the stream fails.
  bool next();
  /// Advances to the next line that has at least one token; false at the end of the input.
  bool next_nonblank();

  long line_number() const { return line_number_; }  ///< 1-based; 0 before the first line
  std::string_view line() const { return line_; }
  const std::vector<std::string_view>& tokens() const { return tokens_; }
  const std::string& source_name() const { return source_name_; }

  /// ParseError at the current line (line 1 if nothing was read yet).
  [[noreturn]] void fail(const std::string& what) const;
  [[noreturn]] void fail_at(long line, const std::string& what) const;

  /// Integer token; on failure "expected <field>, found '<token>'".
  std::int64_t integer(std::string_view token, std::string_view field) const;
  /// Finite real token; on failure "expected <field>, found '<token>'" or "non-finite <field> ...".
  double real(std::string_view token, std::string_view field) const;

  /// A token or line as it may be shown in a message: at most 40 characters, control and
  /// non-ASCII bytes escaped (a binary file must not garble the terminal).
  static std::string quoted(std::string_view text);

 private:
  std::istream& in_;
  std::string source_name_;
  std::string line_;
  std::vector<std::string_view> tokens_;
  long line_number_ = 0;
};

}  // namespace cohaptic
