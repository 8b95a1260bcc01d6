#include "server/served_conditions.h"

#include <fmt/format.h>

#include <set>

#include "common/util/error.h"
#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"

namespace cohaptic {

LinkDelaySettings ServedCondition::link_delay(const LinkDelaySettings& session) const {
  LinkDelaySettings settings = session;
  settings.delay_ms = shift_delay_ms;
  settings.jitter_ms = jitter_ms;
  settings.loss = loss;
  return settings;
}

std::string ServedCondition::describe() const {
  std::string text = protocol == ServeProtocol::p1 ? "P1" : "P0";
  if (shift_delay_ms > 0) text += fmt::format(", shift {:g} ms", shift_delay_ms);
  if (jitter_ms > 0) text += fmt::format(", jitter {:g} ms", jitter_ms);
  if (loss > 0) text += fmt::format(", loss {:g}", loss);
  if (step_nodes > 0) text += fmt::format(", {} held nodes", step_nodes);
  if (sim_rate_hz > 0) text += fmt::format(", simulation capped at {:g} Hz", sim_rate_hz);
  return text;
}

ServedCondition parse_served_condition(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    throw Error(fmt::format(
        "--condition '{}': {} (expected NAME:key=value,... with keys protocol, shift_ms, "
        "jitter_ms, loss, step_nodes, sim_rate_hz)",
        text, why));
  };
  const std::size_t colon = text.find(':');
  ServedCondition condition;
  condition.name = text.substr(0, colon);
  if (condition.name.empty()) fail("no name before ':'");
  if (colon == std::string::npos) return condition;
  std::set<std::string> seen;
  std::size_t begin = colon + 1;
  while (begin < text.size()) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, end - begin);
    begin = end + 1;
    const std::size_t equals = item.find('=');
    if (equals == std::string::npos) fail(fmt::format("'{}' is not key=value", item));
    const std::string key = item.substr(0, equals), value = item.substr(equals + 1);
    if (!seen.insert(key).second) fail(fmt::format("{} is given twice", key));
    const auto number = [&](double low, double high, const char* range) {
      double parsed = 0;
      std::size_t used = 0;
      try {
        parsed = std::stod(value, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != value.size() || value.empty() || !(parsed >= low && parsed <= high))
        fail(fmt::format("{}={} is not {}", key, value, range));
      return parsed;
    };
    if (key == "protocol") {
      if (value != "P0" && value != "P1")
        fail(fmt::format("protocol={} is neither P0 nor P1", value));
      condition.protocol = value == "P0" ? ServeProtocol::p0 : ServeProtocol::p1;
    } else if (key == "shift_ms") {
      condition.shift_delay_ms = number(0, 60'000, "a delay from 0 to 60000 ms");
    } else if (key == "jitter_ms") {
      condition.jitter_ms = number(0, 60'000, "a jitter from 0 to 60000 ms");
    } else if (key == "loss") {
      condition.loss = number(0, 0.999, "a probability in [0, 1)");
    } else if (key == "step_nodes") {
      const double nodes = number(0, 100'000, "a node count from 0 to 100000");
      if (nodes != static_cast<int>(nodes))
        fail(fmt::format("step_nodes={} is not a whole number", value));
      condition.step_nodes = static_cast<int>(nodes);
    } else if (key == "sim_rate_hz") {
      condition.sim_rate_hz = number(0, 1'000'000, "a rate >= 0 Hz");
    } else {
      fail(fmt::format("unknown key {}", key));
    }
  }
  return condition;
}

ConditionSwitch::ConditionSwitch(std::vector<ServedCondition> conditions)
    : conditions_(std::move(conditions)) {
  if (conditions_.empty()) throw Error("a session serves at least one condition");
  std::set<std::string> names;
  for (const ServedCondition& condition : conditions_)
    if (!names.insert(condition.name).second)
      throw Error(fmt::format("two conditions are named '{}'", condition.name));
}

int ConditionSwitch::serve(const std::string& name) {
  for (std::size_t i = 0; i < conditions_.size(); ++i)
    if (conditions_[i].name == name) {
      const std::lock_guard lock(mutex_);
      return switch_to(static_cast<int>(i));
    }
  std::vector<std::string> known;
  for (const ServedCondition& condition : conditions_) known.push_back(condition.name);
  throw Error(fmt::format("no condition named '{}' (this session serves {})", name,
                          fmt::join(known, ", ")));
}

int ConditionSwitch::serve_next() {
  const std::lock_guard lock(mutex_);
  return switch_to((served_.index + 1) % static_cast<int>(conditions_.size()));
}

int ConditionSwitch::switch_to(int index) {
  served_.index = index;
  ++served_.switches;
  history_.push_back({monotonic_now_ns(), index});
  return index;
}

ConditionSwitch::Served ConditionSwitch::served() const {
  const std::lock_guard lock(mutex_);
  return served_;
}

std::vector<ConditionSwitch::Switch> ConditionSwitch::history() const {
  const std::lock_guard lock(mutex_);
  return history_;
}

}  // namespace cohaptic
