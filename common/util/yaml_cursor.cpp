#include "common/util/yaml_cursor.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "common/util/error.h"

namespace cohaptic {

void raise_parse_error(const std::string& file, int line, const std::string& message) {
  throw ParseError(file, line, message);
}

namespace {
// Raisers must not return; this makes sure the compiler knows it too.
[[noreturn]] void raise(YamlErrorRaiser raiser, const std::string& file, int line,
                        const std::string& message) {
  raiser(file, line, message);
  std::abort();
}
}  // namespace

YamlCursor::YamlCursor(YAML::Node node, std::string path, const std::string* file, int line,
                       YamlErrorRaiser raiser)
    : node_(std::move(node)), path_(std::move(path)), file_(file), line_(line), raise_(raiser) {
  if (node_.IsDefined() && node_.Mark().line >= 0) line_ = node_.Mark().line + 1;
}

std::string YamlCursor::location() const { return fmt::format("{}:{}: {}", *file_, line_, path_); }

void YamlCursor::fail(const std::string& expected) const {
  raise(raise_, *file_, line_,
        fmt::format("{}: expected {}, found {}", path_.empty() ? "(top level)" : path_, expected,
                    describe()));
}

void YamlCursor::fail_message(const std::string& message) const {
  raise(raise_, *file_, line_,
        fmt::format("{}: {}", path_.empty() ? "(top level)" : path_, message));
}

std::optional<YamlCursor> YamlCursor::find(const std::string& key) const {
  if (!node_.IsMap()) fail("a map");
  const YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) return std::nullopt;
  return YamlCursor(child, join(key), file_, line_, raise_);
}

YamlCursor YamlCursor::at(const std::string& key) const {
  if (auto child = find(key)) return *child;
  fail_message(fmt::format("missing required key '{}'", key));
}

void YamlCursor::only_keys(std::initializer_list<const char*> allowed) const {
  if (!node_.IsMap()) fail("a map");
  const std::set<std::string> known(allowed.begin(), allowed.end());
  for (const auto& entry : node_) {
    const std::string key = key_text(entry.first);
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      YamlCursor(entry.first, join(key), file_, line_, raise_)
          .fail_message(fmt::format("unknown key (allowed here: {})", list));
    }
  }
}

std::vector<std::string> YamlCursor::keys() const {
  if (!node_.IsMap()) fail("a map");
  std::vector<std::string> out;
  for (const auto& entry : node_) out.push_back(key_text(entry.first));
  return out;
}

std::vector<YamlCursor> YamlCursor::items() const {
  if (!node_.IsSequence()) fail("a list");
  std::vector<YamlCursor> out;
  for (std::size_t i = 0; i < node_.size(); ++i)
    out.emplace_back(node_[i], fmt::format("{}[{}]", path_, i), file_, line_, raise_);
  return out;
}

std::string YamlCursor::text() const {
  if (!node_.IsScalar()) fail("a string");
  return node_.Scalar();
}

double YamlCursor::number() const {
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

double YamlCursor::positive(const std::string& expected) const {
  const double v = number();
  if (!(v > 0)) fail(expected);
  return v;
}

double YamlCursor::number_in(double low, double high, bool low_open, bool high_open,
                             const std::string& expected) const {
  const double v = number();
  if ((low_open ? v <= low : v < low) || (high_open ? v >= high : v > high)) fail(expected);
  return v;
}

bool YamlCursor::boolean() const {
  if (!node_.IsScalar()) fail("true or false");
  try {
    return node_.as<bool>();
  } catch (const YAML::Exception&) {
    fail("true or false");
  }
}

std::string YamlCursor::choice(std::initializer_list<const char*> options) const {
  const std::string v = text();
  std::string list;
  for (const char* o : options) {
    if (v == o) return v;
    list += (list.empty() ? "" : " | ") + std::string(o);
  }
  fail(list);
}

std::int64_t YamlCursor::integer() const {
  if (!node_.IsScalar()) fail("an integer");
  try {
    return node_.as<std::int64_t>();
  } catch (const YAML::Exception&) {
    fail("an integer");
  }
}

Eigen::Vector3d YamlCursor::vec3() const {
  if (!node_.IsSequence() || node_.size() != 3) fail("a list of 3 numbers");
  const auto parts = items();
  return {parts[0].number(), parts[1].number(), parts[2].number()};
}

Eigen::Vector3d YamlCursor::direction(const std::string& expected) const {
  // Divided by its largest component first: the length of (1e200, 1e200, 0) squares past
  // the largest double, and that of (1.7e308, 1.7e308, 0) is itself past it; either would
  // make the unit vector zero.
  const Eigen::Vector3d v = vec3();
  const double largest = v.cwiseAbs().maxCoeff();
  const Eigen::Vector3d scaled = v / largest;
  if (!(largest > 0) || !(largest * scaled.norm() >= 1e-12)) fail(expected);
  return scaled.normalized();
}

std::string YamlCursor::key_text(const YAML::Node& key) const {
  if (!key.IsScalar())
    YamlCursor(key, path_, file_, line_, raise_).fail("a map whose keys are names");
  return key.Scalar();
}

std::string YamlCursor::join(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

std::string YamlCursor::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsSequence()) return fmt::format("a list of {}", node_.size());
  return "a map";
}

YAML::Node load_yaml(const std::string& text, const std::string& file, YamlErrorRaiser raiser) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    raise(raiser, file, e.mark.line + 1, fmt::format("YAML syntax error: {}", e.msg));
  }
}

std::string read_text_file(const std::string& file, YamlErrorRaiser raiser) {
  std::ifstream in(file);
  if (!in) raise(raiser, file, 0, fmt::format("cannot open the file: {}", std::strerror(errno)));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace cohaptic
