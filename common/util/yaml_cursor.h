// YamlCursor: a YAML node together with where it is (file, line and key path), so that
// every complaint about a hand-written file (scenes, trajectories, studies) names the file,
// the line, the key path (e.g. objects[0].material.poisson_ratio), what was expected and
// what was found.
//
// Errors go through a raiser chosen by the caller (a scene raises SceneError, the device
// files ParseError); the message is always "file:line: key.path: ...".
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic {

/// Throws the caller's error type for "file:line: message". Must not return.
using YamlErrorRaiser = void (*)(const std::string& file, int line, const std::string& message);

/// The default raiser: ParseError.
[[noreturn]] void raise_parse_error(const std::string& file, int line, const std::string& message);

class YamlCursor {
 public:
  /// `file` must outlive the cursor and every cursor derived from it.
  YamlCursor(YAML::Node node, std::string path, const std::string* file, int line,
             YamlErrorRaiser raise = raise_parse_error);

  const std::string& path() const { return path_; }
  /// "file:line: key.path", for messages raised later (e.g. a selector that selects nothing).
  std::string location() const;
  int line() const { return line_; }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }

  /// Throws ParseError "file:line: path: expected <expected>, found <what is there>".
  [[noreturn]] void fail(const std::string& expected) const;
  /// Throws ParseError "file:line: path: <message>".
  [[noreturn]] void fail_message(const std::string& message) const;

  /// The child at `key`, or nothing if absent or null. Fails unless this is a map.
  std::optional<YamlCursor> find(const std::string& key) const;
  /// The child at `key`; a missing key is an error naming it.
  YamlCursor at(const std::string& key) const;
  /// Rejects keys outside `allowed`, naming the first unknown one and the allowed set.
  void only_keys(std::initializer_list<const char*> allowed) const;
  /// The keys of a map, in file order.
  std::vector<std::string> keys() const;
  /// The items of a list.
  std::vector<YamlCursor> items() const;

  std::string text() const;
  /// A finite number.
  double number() const;
  /// A finite number > 0; `expected` describes it in the message.
  double positive(const std::string& expected) const;
  /// A finite number in the interval from low to high, each end open or closed.
  double number_in(double low, double high, bool low_open, bool high_open,
                   const std::string& expected) const;
  std::int64_t integer() const;
  bool boolean() const;
  /// One of `options`; the message lists them.
  std::string choice(std::initializer_list<const char*> options) const;
  /// A list of exactly 3 finite numbers.
  Eigen::Vector3d vec3() const;
  /// A vec3() of length 1e-12 or more, returned scaled to unit length; `expected` describes
  /// it in the message. Huge components are fine (the length is computed without overflow).
  Eigen::Vector3d direction(const std::string& expected) const;

 private:
  std::string join(const std::string& key) const;
  /// The map key `key` as text; a key that is a list or a map fails, naming where.
  std::string key_text(const YAML::Node& key) const;
  std::string describe() const;

  YAML::Node node_;
  std::string path_;
  const std::string* file_;
  int line_;
  YamlErrorRaiser raise_;
};

/// Parses `text` as YAML; a syntax error is raised naming `file` and the line.
YAML::Node load_yaml(const std::string& text, const std::string& file,
                     YamlErrorRaiser raise = raise_parse_error);

/// The whole file as text; a file that cannot be opened is raised naming it.
std::string read_text_file(const std::string& file, YamlErrorRaiser raise = raise_parse_error);

}  // namespace cohaptic
