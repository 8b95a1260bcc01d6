#include "common/haptics/trajectory.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <optional>

#include "common/util/yaml_cursor.h"
#include "common/util/error.h"

namespace cohaptic {

Trajectory::Trajectory(std::vector<double> times, std::vector<Eigen::Vector3d> points,
                       std::string source, std::vector<std::uint32_t> buttons)
    : times_(std::move(times)),
      points_(std::move(points)),
      source_(std::move(source)),
      buttons_(std::move(buttons)) {
  if (times_.empty() || times_.size() != points_.size())
    throw Error(fmt::format(
        "trajectory {}: expected as many knot times as points (at least one), found {} and {}",
        source_, times_.size(), points_.size()));
  if (!buttons_.empty() && buttons_.size() != times_.size())
    throw Error(
        fmt::format("trajectory {}: expected no buttons or one entry per knot ({}), found {}",
                    source_, times_.size(), buttons_.size()));
  if (times_[0] != 0.0)
    throw Error(fmt::format("trajectory {}: the first knot must be at t = 0, found {}", source_,
                            times_[0]));
  for (std::size_t i = 0; i < times_.size(); ++i) {
    if (!std::isfinite(times_[i]) || !points_[i].allFinite())
      throw Error(fmt::format("trajectory {}: knot {} is not finite", source_, i));
    if (i > 0 && !(times_[i] > times_[i - 1]))
      throw Error(fmt::format("trajectory {}: knot times must increase, found {} after {}", source_,
                              times_[i], times_[i - 1]));
  }
}

std::size_t Trajectory::segment_at(double t) const {
  // The last knot with time <= t; callers ensure 0 <= t < duration(), so it is not the last.
  const auto after = std::upper_bound(times_.begin(), times_.end(), t);
  return static_cast<std::size_t>(after - times_.begin()) - 1;
}

Eigen::Vector3d Trajectory::position(double t) const {
  if (!(t > 0.0)) return points_.front();  // also NaN
  if (t >= times_.back()) return points_.back();
  const std::size_t i = segment_at(t);
  const double s = (t - times_[i]) / (times_[i + 1] - times_[i]);
  return points_[i] + s * (points_[i + 1] - points_[i]);
}

Eigen::Vector3d Trajectory::velocity(double t) const {
  if (!(t >= 0.0) || t >= times_.back()) return Eigen::Vector3d::Zero();
  const std::size_t i = segment_at(t);
  return (points_[i + 1] - points_[i]) / (times_[i + 1] - times_[i]);
}

std::uint32_t Trajectory::buttons(double t) const {
  if (buttons_.empty() || !(t >= 0.0)) return 0;
  if (t >= times_.back()) return buttons_.back();
  return buttons_[segment_at(t)];
}

namespace {

using Cursor = YamlCursor;

constexpr std::int64_t kMaxRepeat = 100000;

// One segment as read from the file, lengths already in metres.
struct Segment {
  enum class Kind { move_to, move_by, press, release, hold } kind;
  Eigen::Vector3d vector =
      Eigen::Vector3d::Zero();  // target (move_to), offset (move_by), direction (press)
  bool has_direction = false;   // press: direction given explicitly
  double amount = 0;            // depth (press), distance (release), seconds (hold)
  double speed = 0;             // m/s
  std::uint32_t buttons = 0;    // held during the segment
  Cursor where;                 // for errors found while playing (release before press)
};

double metres_per(const Cursor& units) {
  const std::string u = units.text();
  if (u == "m") return 1.0;
  if (u == "cm") return 0.01;
  if (u == "mm") return 0.001;
  units.fail("one of m, cm, mm");
}

Segment parse_segment(const Cursor& c, double scale) {
  if (!c.is_map()) c.fail("a map with one of move_to, move_by, press, release or hold");
  const char* kinds[] = {"move_to", "move_by", "press", "release", "hold"};
  std::optional<Cursor> kind_cursor;
  std::string kind;
  for (const char* k : kinds) {
    if (auto found = c.find(k)) {
      if (kind_cursor)
        found->fail_message(
            fmt::format("a segment has exactly one of move_to, move_by, press, release or hold; "
                        "this one also has {}",
                        kind));
      kind_cursor = found;
      kind = k;
    }
  }
  if (!kind_cursor) c.fail("a map with one of move_to, move_by, press, release or hold");

  Segment s{Segment::Kind::hold, Eigen::Vector3d::Zero(), false, 0, 0, 0, c};
  if (auto buttons = c.find("buttons")) {
    const std::int64_t mask = buttons->integer();
    if (mask < 0 || mask > std::int64_t{0xffffffff})
      buttons->fail("a button mask from 0 to 4294967295 (bit i = button i)");
    s.buttons = static_cast<std::uint32_t>(mask);
  }
  auto speed = [&] {
    return c.at("speed").positive("a positive speed (in units per second)") * scale;
  };
  if (kind == "move_to" || kind == "move_by") {
    c.only_keys({kind.c_str(), "speed", "buttons"});
    s.kind = kind == "move_to" ? Segment::Kind::move_to : Segment::Kind::move_by;
    s.vector = kind_cursor->vec3() * scale;
    s.speed = speed();
  } else if (kind == "press") {
    c.only_keys({"press", "speed", "direction", "buttons"});
    s.kind = Segment::Kind::press;
    s.amount = kind_cursor->positive("a positive depth") * scale;
    s.speed = speed();
    if (auto direction = c.find("direction")) {
      const Eigen::Vector3d d = direction->vec3();
      if (!(d.norm() > 1e-12)) direction->fail("a non-zero direction vector");
      s.vector = d.normalized();
      s.has_direction = true;
    }
  } else if (kind == "release") {
    c.only_keys({"release", "speed", "buttons"});
    s.kind = Segment::Kind::release;
    s.amount = kind_cursor->positive("a positive distance") * scale;
    s.speed = speed();
  } else {
    c.only_keys({"hold", "buttons"});
    s.kind = Segment::Kind::hold;
    s.amount = kind_cursor->positive("a positive duration in s");
  }
  return s;
}

}  // namespace

Trajectory parse_trajectory(const std::string& yaml, const std::string& name) {
  const Cursor top(load_yaml(yaml, name), "", &name, 1);
  if (!top.is_map()) top.fail("a map with start and segments");
  top.only_keys({"units", "start", "segments", "repeat", "hand"});

  const double scale = top.find("units") ? metres_per(top.at("units")) : 1.0;
  const Eigen::Vector3d start = top.at("start").vec3() * scale;

  const Cursor segments_cursor = top.at("segments");
  std::vector<Segment> segments;
  for (const Cursor& item : segments_cursor.items()) segments.push_back(parse_segment(item, scale));
  if (segments.empty()) segments_cursor.fail("at least one segment");

  std::int64_t repeat = 1;
  if (auto r = top.find("repeat")) {
    repeat = r->integer();
    if (repeat < 1 || repeat > kMaxRepeat)
      r->fail(fmt::format("an integer from 1 to {}", kMaxRepeat));
  }
  // `hand` is validated by parse_hand_parameters (hand_model.h); a script ignores it.

  std::vector<double> times{0.0};
  std::vector<Eigen::Vector3d> points{start};
  std::vector<std::uint32_t> buttons{0};  // buttons[i]: held from knot i on
  bool any_buttons = false;
  Eigen::Vector3d here = start;
  double now = 0.0;
  std::optional<Eigen::Vector3d> press_direction;
  // The segment being played: its buttons are held from the knot it starts at.
  std::uint32_t held = 0;
  auto add_knot = [&] {
    buttons.back() = held;
    times.push_back(now);
    points.push_back(here);
    buttons.push_back(held);  // from the end on, until a next segment starts here
  };
  auto go = [&](const Eigen::Vector3d& target, double speed) {
    const double length = (target - here).norm();
    if (length == 0.0) return;  // already there: takes no time, adds no knot
    const double then = now + length / speed;
    here = target;
    if (!(then > now)) {  // too short to advance the clock at this time: arrive at once
      points.back() = here;
      return;
    }
    now = then;
    add_knot();
  };
  for (std::int64_t r = 0; r < repeat; ++r) {
    for (const Segment& s : segments) {
      held = s.buttons;
      any_buttons = any_buttons || held != 0;
      switch (s.kind) {
        case Segment::Kind::move_to:
          go(s.vector, s.speed);
          break;
        case Segment::Kind::move_by:
          go(here + s.vector, s.speed);
          break;
        case Segment::Kind::press:
          press_direction =
              s.has_direction ? s.vector : press_direction.value_or(Eigen::Vector3d(0, 0, -1));
          go(here + s.amount * *press_direction, s.speed);
          break;
        case Segment::Kind::release:
          if (!press_direction)
            s.where.fail_message(
                "release before any press (release moves back along the last press direction)");
          go(here - s.amount * *press_direction, s.speed);
          break;
        case Segment::Kind::hold:
          now += s.amount;
          add_knot();
          break;
      }
    }
  }
  if (!any_buttons) buttons.clear();
  return Trajectory(std::move(times), std::move(points), name, std::move(buttons));
}

Trajectory load_trajectory(const std::filesystem::path& file) {
  const std::string name = file.string();
  return parse_trajectory(read_text_file(name), name);
}

}  // namespace cohaptic
