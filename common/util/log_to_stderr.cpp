#include "common/util/log_to_stderr.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace cohaptic {

void log_to_stderr() {
  spdlog::set_default_logger(spdlog::stderr_color_mt("cohaptic"));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
}

}  // namespace cohaptic
