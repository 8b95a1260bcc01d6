#include "client/device/trajectory_reach.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

namespace cohaptic {

std::string trajectory_reach_warning(const Trajectory& path, const Eigen::AlignedBox3d& scene) {
  if (scene.isEmpty()) return "";
  // Sampled every millisecond (at most 100,000 samples): closer than a diagonal is enough.
  constexpr int kMaxSamples = 100'000;
  const double duration = path.duration();
  const int samples = std::clamp(static_cast<int>(duration * 1e3), 1, kMaxSamples);
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= samples; ++k)
    nearest = std::min(nearest, scene.exteriorDistance(path.position(duration * k / samples)));
  const double diagonal = scene.diagonal().norm();
  if (nearest <= diagonal) return "";
  const Eigen::Vector3d low = scene.min(), high = scene.max();
  return fmt::format(
      "the tool's path ({}) stays {:.3g} m or more from the scene, which spans [{:.3g}, {:.3g}, "
      "{:.3g}] to "
      "[{:.3g}, {:.3g}, {:.3g}] m: it will touch nothing (is the file's unit right? units: mm or "
      "m)",
      path.source(), nearest, low.x(), low.y(), low.z(), high.x(), high.y(), high.z());
}

}  // namespace cohaptic
