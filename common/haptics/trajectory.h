// Trajectory: a scripted tool path, piecewise linear in time, loaded from a small YAML file.
//
//   # units of lengths in this file (m, cm, mm; default m); times in s, speeds in <units>/s
//   units: mm
//   start: [0, 0, 20]          # where the tool is at t = 0 (required)
//   segments:                  # played in order (at least one)
//     - {move_to: [0, 0, 2], speed: 20}                # straight line to a point, at a
//                                                      #   constant speed
//     - {press: 15, speed: 5, direction: [0, 0, -1]}   # move by 15 along direction (normalised;
//                                                      #   default: the previous press's, else -z)
//     - {hold: 1.0}                                    # stay still for 1 s
//     - {release: 15, speed: 5}                        # back by 15 along the last press direction
//     - {move_by: [10, 0, 0], speed: 10}               # straight line by an offset
//     - {hold: 0.5, buttons: 1}                        # any segment: the device buttons held
//                                                      #   during it (bit i = button i; default 0)
//   repeat: 3                  # play the segments this many times (default 1); each repetition
//                              #   starts where the last ended (move_to stays absolute)
//   hand: {mass: 0.2, stiffness: 300, damping: 8}     # optional, SI; read by hand_model.h only
//
// Units: positions in m (converted on load), times in s, velocities in m/s.
// Invariants: knot times start at 0 and strictly increase; there is at least one knot.
// position(t) is the start for t <= 0 and the last knot after the end; velocity(t) is the
// slope of the segment [t_i, t_i+1) holding t, zero before 0 and from the end on.
// buttons(t) are the buttons of the segment holding t: none before 0, the last segment's from
// the end on (a hand that ends a script holding a button keeps holding it). A segment that
// takes no time (a move to where the tool already is) holds its buttons for no time.
// position() and velocity() neither allocate nor lock (binary search over the knots).
// Errors: ParseError naming the file, the line and the key path, what was expected and found.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace cohaptic {

class Trajectory {
 public:
  /// From knots: times[0] == 0, strictly increasing, finite; as many points as times (>= 1).
  /// `buttons`, empty (none ever held) or one per knot: buttons[i] are held from knot i to
  /// knot i + 1, the last from the end on. Throws Error otherwise. `source` names the
  /// trajectory in logs (e.g. the file).
  Trajectory(std::vector<double> times, std::vector<Eigen::Vector3d> points, std::string source,
             std::vector<std::uint32_t> buttons = {});

  /// Tool position at time t [m].
  Eigen::Vector3d position(double t) const;
  /// Tool velocity at time t [m/s].
  Eigen::Vector3d velocity(double t) const;
  /// Device buttons held at time t (bit i = button i).
  std::uint32_t buttons(double t) const;
  /// Time of the last knot [s] (0 for a single point).
  double duration() const { return times_.back(); }

  const std::vector<double>& knot_times() const { return times_; }
  const std::vector<Eigen::Vector3d>& knot_points() const { return points_; }
  const std::string& source() const { return source_; }

 private:
  /// Index i of the segment [t_i, t_i+1) holding t, for 0 <= t < duration().
  std::size_t segment_at(double t) const;

  std::vector<double> times_;
  std::vector<Eigen::Vector3d> points_;
  std::string source_;
  std::vector<std::uint32_t> buttons_;  // empty, or one per knot
};

/// Reads and validates a trajectory file (format above).
Trajectory load_trajectory(const std::filesystem::path& file);

/// Parses trajectory text; `name` stands for the file in messages and in source().
Trajectory parse_trajectory(const std::string& yaml, const std::string& name);

}  // namespace cohaptic
