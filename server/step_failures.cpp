#include "server/step_failures.h"

#include <fmt/format.h>

namespace cohaptic {

std::optional<std::string> StepFailures::failed(std::int64_t now_ns, const std::string& what) {
  ++total_;
  ++consecutive_;
  ++since_logged_;
  last_error_ = what;
  if (last_logged_ns_ && now_ns - *last_logged_ns_ < kStepFailureLogInterval_ns)
    return std::nullopt;
  std::string line = last_logged_ns_
                         ? fmt::format(
                               "simulation step failed {} times since the last report ({} in a "
                               "row), tools released: {}",
                               since_logged_, consecutive_, what)
                         : fmt::format("simulation step failed, tools released: {}", what);
  last_logged_ns_ = now_ns;
  since_logged_ = 0;
  return line;
}

}  // namespace cohaptic
