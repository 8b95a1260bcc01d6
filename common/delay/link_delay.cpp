#include "common/delay/link_delay.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/util/error.h"

namespace cohaptic {

std::string LinkDelaySettings::describe() const {
  return fmt::format("{:g} ms + U(0, {:g}) ms jitter, {:g} % loss, {:g} % reordered, seed {}",
                     delay_ms, jitter_ms, 100 * loss, 100 * reorder, seed);
}

void validate(const LinkDelaySettings& s) {
  if (!std::isfinite(s.delay_ms) || s.delay_ms < 0 || s.delay_ms > 10000)
    throw Error(fmt::format("shift delay must be between 0 and 10000 ms, got {}", s.delay_ms));
  if (!std::isfinite(s.jitter_ms) || s.jitter_ms < 0 || s.jitter_ms > 10000)
    throw Error(fmt::format("jitter must be between 0 and 10000 ms, got {}", s.jitter_ms));
  if (!(s.loss >= 0 && s.loss < 1))
    throw Error(fmt::format("loss must be a probability in [0, 1), got {}", s.loss));
  if (!(s.reorder >= 0 && s.reorder < 1))
    throw Error(fmt::format("reordering must be a probability in [0, 1), got {}", s.reorder));
}

LinkDelay::LinkDelay(const LinkDelaySettings& settings, bool ordered)
    : settings_(settings), ordered_(ordered), rng_(settings.seed) {
  validate(settings_);
}

void LinkDelay::set_settings(const LinkDelaySettings& settings) {
  validate(settings);
  settings_ = settings;
}

std::optional<std::int64_t> LinkDelay::delay_ns(std::int64_t now_ns) {
  ++counters_.messages;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double lose = unit(rng_), shuffle = unit(rng_), jitter = unit(rng_);
  if (!ordered_ && lose < settings_.loss) {
    ++counters_.dropped;
    return std::nullopt;
  }
  double delay_ms = settings_.delay_ms + jitter * settings_.jitter_ms;
  if (!ordered_ && shuffle < settings_.reorder) {
    delay_ms += 2 * settings_.jitter_ms + 1;
    ++counters_.reordered;
  }
  auto delay = static_cast<std::int64_t>(delay_ms * 1e6);
  if (ordered_) {  // strictly after the previous delivery: timers due at one instant may fire in
                   // any order
    if (delivered_before_) delay = std::max(delay, last_delivery_ns_ - now_ns + 1);
    last_delivery_ns_ = now_ns + delay;
    delivered_before_ = true;
  }
  counters_.delay_sum_ms += static_cast<double>(delay) * 1e-6;
  counters_.delay_max_ms = std::max(counters_.delay_max_ms, static_cast<double>(delay) * 1e-6);
  return delay;
}

}  // namespace cohaptic
