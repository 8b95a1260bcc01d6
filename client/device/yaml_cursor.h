// A YAML node together with where it is (file, line and key path), for the device files
// (trajectories, hand parameters), so that every complaint names the file, the line, the
// key path (e.g. segments[1].speed), what was expected and what was found.
//
// Errors are ParseError("file", line, "key.path: expected X, found Y"). Deliberately a
// small sibling of the scene loader's private cursor (common/scene/load_scene.cpp), kept in
// its own namespace so that a shared one can later replace it without a clash.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace cohaptic::device_yaml {

class Cursor {
 public:
  /// `file` must outlive the cursor and every cursor derived from it.
  Cursor(YAML::Node node, std::string path, const std::string* file, int line);

  const std::string& path() const { return path_; }
  int line() const { return line_; }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }

  /// Throws ParseError "file:line: path: expected <expected>, found <what is there>".
  [[noreturn]] void fail(const std::string& expected) const;
  /// Throws ParseError "file:line: path: <message>".
  [[noreturn]] void fail_message(const std::string& message) const;

  /// The child at `key`, or nothing if absent or null. Fails unless this is a map.
  std::optional<Cursor> find(const std::string& key) const;
  /// The child at `key`; a missing key is an error naming it.
  Cursor at(const std::string& key) const;
  /// Rejects keys outside `allowed`, naming the first unknown one and the allowed set.
  void only_keys(std::initializer_list<const char*> allowed) const;
  /// The keys of a map, in file order.
  std::vector<std::string> keys() const;
  /// The items of a list.
  std::vector<Cursor> items() const;

  std::string text() const;
  /// A finite number.
  double number() const;
  /// A finite number > 0; `expected` describes it in the message.
  double positive(const std::string& expected) const;
  std::int64_t integer() const;
  /// A list of exactly 3 finite numbers.
  Eigen::Vector3d vec3() const;

 private:
  std::string join(const std::string& key) const;
  std::string describe() const;

  YAML::Node node_;
  std::string path_;
  const std::string* file_;
  int line_;
};

/// Parses `text` as YAML; a syntax error becomes a ParseError naming `file` and the line.
YAML::Node load_yaml(const std::string& text, const std::string& file);

/// The whole file as text; a file that cannot be opened is a ParseError naming it.
std::string read_text_file(const std::string& file);

}  // namespace cohaptic::device_yaml
