#include "client/device/yaml_cursor.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <set>
#include <sstream>

#include "common/util/error.h"

namespace cohaptic::device_yaml {

Cursor::Cursor(YAML::Node node, std::string path, const std::string* file, int line)
    : node_(std::move(node)), path_(std::move(path)), file_(file), line_(line) {
  if (node_.IsDefined() && node_.Mark().line >= 0) line_ = node_.Mark().line + 1;
}

void Cursor::fail(const std::string& expected) const {
  throw ParseError(*file_, line_,
                   fmt::format("{}: expected {}, found {}", path_.empty() ? "(top level)" : path_, expected, describe()));
}

void Cursor::fail_message(const std::string& message) const {
  throw ParseError(*file_, line_, fmt::format("{}: {}", path_.empty() ? "(top level)" : path_, message));
}

std::optional<Cursor> Cursor::find(const std::string& key) const {
  if (!node_.IsMap()) fail("a map");
  const YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) return std::nullopt;
  return Cursor(child, join(key), file_, line_);
}

Cursor Cursor::at(const std::string& key) const {
  if (auto child = find(key)) return *child;
  fail_message(fmt::format("missing required key '{}'", key));
}

void Cursor::only_keys(std::initializer_list<const char*> allowed) const {
  if (!node_.IsMap()) fail("a map");
  const std::set<std::string> known(allowed.begin(), allowed.end());
  for (const auto& entry : node_) {
    const auto key = entry.first.as<std::string>();
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      Cursor(entry.first, join(key), file_, line_).fail_message(fmt::format("unknown key (allowed here: {})", list));
    }
  }
}

std::vector<std::string> Cursor::keys() const {
  if (!node_.IsMap()) fail("a map");
  std::vector<std::string> out;
  for (const auto& entry : node_) out.push_back(entry.first.as<std::string>());
  return out;
}

std::vector<Cursor> Cursor::items() const {
  if (!node_.IsSequence()) fail("a list");
  std::vector<Cursor> out;
  for (std::size_t i = 0; i < node_.size(); ++i) out.emplace_back(node_[i], fmt::format("{}[{}]", path_, i), file_, line_);
  return out;
}

std::string Cursor::text() const {
  if (!node_.IsScalar()) fail("a string");
  return node_.Scalar();
}

double Cursor::number() const {
  if (!node_.IsScalar()) fail("a number");
  double v = 0;
  try {
    v = node_.as<double>();
  } catch (const YAML::Exception&) {
    fail("a number");
  }
  if (!std::isfinite(v)) fail("a finite number");
  return v;
}

double Cursor::positive(const std::string& expected) const {
  const double v = number();
  if (!(v > 0)) fail(expected);
  return v;
}

std::int64_t Cursor::integer() const {
  if (!node_.IsScalar()) fail("an integer");
  try {
    return node_.as<std::int64_t>();
  } catch (const YAML::Exception&) {
    fail("an integer");
  }
}

Eigen::Vector3d Cursor::vec3() const {
  if (!node_.IsSequence() || node_.size() != 3) fail("a list of 3 numbers");
  const auto parts = items();
  return {parts[0].number(), parts[1].number(), parts[2].number()};
}

std::string Cursor::join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

std::string Cursor::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsSequence()) return fmt::format("a list of {}", node_.size());
  return "a map";
}

YAML::Node load_yaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ParseError(file, e.mark.line + 1, fmt::format("YAML syntax error: {}", e.msg));
  }
}

std::string read_text_file(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ParseError(file, 0, fmt::format("cannot open the file: {}", std::strerror(errno)));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace cohaptic::device_yaml
