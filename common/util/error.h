// Typed errors raised by cohaptic's common library.
//
// Every error says what was wrong and where: a file and line for parsers, a key path
// for scenes, a node or element id for meshes and factorisations. Callers at program
// level print what() and exit non-zero; nothing below them swallows an error.
#pragma once

#include <fmt/format.h>
#include <stdexcept>
#include <string>

namespace cohaptic {

/// Base of all cohaptic errors.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file could not be read or parsed: the message starts with "file:line:".
class ParseError : public Error {
 public:
  ParseError(const std::string& file, long line, const std::string& what)
      : Error(line > 0 ? fmt::format("{}:{}: {}", file, line, what)
                       : fmt::format("{}: {}", file, what)),
        file_(file),
        line_(line) {}
  const std::string& file() const { return file_; }
  long line() const { return line_; }

 private:
  std::string file_;
  long line_;
};

/// A mesh is unusable (inverted or degenerate element, non-manifold volume, ...).
class MeshError : public Error {
 public:
  using Error::Error;
};

/// A numerical failure: a matrix that should be positive definite is not, a solve failed.
class NumericalError : public Error {
 public:
  using Error::Error;
};

}  // namespace cohaptic
