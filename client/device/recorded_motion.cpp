#include "client/device/recorded_motion.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <string>
#include <vector>

#include "common/util/error.h"
#include "proto/record/recording.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {
namespace {

// Adds a knot unless it is not later than the last (repeated samples of one time).
void add_knot(std::vector<double>& times, std::vector<Eigen::Vector3d>& points, double t,
              const Eigen::Vector3d& p) {
  if (!times.empty() && t <= times.back()) return;
  times.push_back(t);
  points.push_back(p);
}

// The slot of `user` in a server recording: a slot number, or the name a user joined with
// (0 if none is given).
int slot_of(const record::Recording& rec, const std::string& user) {
  if (user.empty()) return 0;
  if (user.find_first_not_of("0123456789") == std::string::npos && user.size() < 4)
    return std::stoi(user);
  std::vector<std::string> names;
  for (const record::SessionEvent& event : rec.events) {
    if (event.kind() != "user_joined" || !event.has_slot()) continue;
    if (event.user() == user) return static_cast<int>(event.slot());
    names.push_back(fmt::format("'{}' (slot {})", event.user(), event.slot()));
  }
  throw Error(fmt::format(
      "{}: no user '{}' joined this session; give a slot number or one of: {}", rec.file.string(),
      user, names.empty() ? "(no joins recorded)" : fmt::format("{}", fmt::join(names, ", "))));
}

}  // namespace

Trajectory recorded_motion(const std::filesystem::path& file, const std::string& user) {
  const record::Recording rec = record::read_recording(file);
  std::vector<double> times;
  std::vector<Eigen::Vector3d> points;
  if (!rec.ticks.empty()) {
    std::int64_t start = -1;
    for (const record::HapticTick& tick : rec.ticks)
      if (tick.own_valid()) {
        if (start < 0) start = tick.time_ns();
        add_knot(times, points, static_cast<double>(tick.time_ns() - start) * 1e-9,
                 wire::from_wire(tick.own()));
      }
  } else {
    const int slot = slot_of(rec, user);
    std::int64_t start = -1;
    for (const record::SimulationStep& step : rec.steps)
      for (const record::ToolInput& tool : step.tools())
        if (static_cast<int>(tool.slot()) == slot && tool.known()) {
          if (start < 0) start = step.time_ns();
          add_knot(times, points, static_cast<double>(step.time_ns() - start) * 1e-9,
                   wire::from_wire(tool.position()));
        }
  }
  if (times.empty())
    throw Error(fmt::format("{}: no recorded tool positions{}", file.string(),
                            user.empty() ? "" : " for user " + user));
  return Trajectory(std::move(times), std::move(points), "replay:" + file.string());
}

}  // namespace cohaptic
