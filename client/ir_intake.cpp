#include "client/ir_intake.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>
#include <vector>

#include "common/util/error.h"
#include "common/util/stopwatch.h"
#include "common/ir/warm_start_sphere_contact.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

bool IrIntake::receive(const wire::IntermediateRepresentation& message, std::size_t bytes,
                       std::int64_t arrival_ns) {
  warmed_.reset();
  try {
    IntermediateRepresentation ir = wire::from_wire(message);
    if (auto* fem = std::get_if<CondensedFemIr>(&ir.body); fem && fem->compliance_rows) {
      const double start_us = thread_cpu_us();
      condensation_.complete(*fem);
      condense_us_.record(std::llround(thread_cpu_us() - start_us));
    }
    PreparedIR prepared_ir = prepare_ir(std::move(ir));
    warm(prepared_ir);
    auto prepared = std::make_unique<const PreparedIR>(std::move(prepared_ir));
    to_haptic_.back() = make_ir_slot(std::move(prepared), arrival_ns);
    to_haptic_.publish();
  } catch (const Error& e) {
    ++rejected_;
    spdlog::warn("IR rejected: {}", e.what());
    return false;
  }
  ++received_;
  bytes_ += bytes;
  if (!first_ns_) first_ns_ = arrival_ns;
  last_ns_ = arrival_ns;
  return true;
}

bool IrIntake::receive_compressed(const wire::CompressedIr& block, std::size_t bytes,
                                  std::int64_t arrival_ns) {
  wire::IntermediateRepresentation message;
  try {
    const double start_us = thread_cpu_us();
    message = stream_.open(block);
    inflate_us_.record(std::llround(thread_cpu_us() - start_us));
  } catch (const Error& e) {
    ++rejected_;
    spdlog::warn("IR rejected: {}", e.what());
    return false;
  }
  receive(message, bytes, arrival_ns);
  return true;
}

void IrIntake::see_own_tool(const Eigen::Vector3d& position, bool valid) {
  own_ = valid ? std::optional(position) : std::nullopt;
}

void IrIntake::see_remote_tool(std::uint32_t user, const Eigen::Vector3d& position, bool valid) {
  if (user < remotes_.size()) remotes_[user] = valid ? std::optional(position) : std::nullopt;
}

void IrIntake::warm(PreparedIR& prepared) {
  if (!own_) return;
  std::vector<Eigen::Vector3d> remotes;
  for (int r = 0; r < remote_count(prepared.ir); ++r) {
    const auto user = static_cast<std::size_t>(remote_user(prepared.ir, r));
    remotes.push_back(user < remotes_.size() && remotes_[user]
                          ? *remotes_[user]
                          : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  if (!warm_start_sphere_contact(prepared, *own_, remotes)) return;
  record::WarmStart& warmed = warmed_.emplace();
  *warmed.mutable_own() = wire::to_wire(*own_);
  for (const Eigen::Vector3d& remote : remotes) *warmed.add_remotes() = wire::to_wire(remote);
}

nlohmann::json IrIntake::report() const {
  const double span_s = static_cast<double>(last_ns_ - first_ns_) * 1e-9;
  return {{"received", received_},
          {"condensed", condense_us_.count()},
          {"condense_cpu_us_p50", condense_us_.quantile(0.5)},
          {"condense_cpu_us_max", condense_us_.max()},
          {"inflated", inflate_us_.count()},
          {"inflate_cpu_us_p50", inflate_us_.quantile(0.5)},
          {"inflate_cpu_us_max", inflate_us_.max()},
          {"rejected", rejected_},
          {"bytes", bytes_},
          {"bytes_per_s", span_s > 0 ? static_cast<double>(bytes_) / span_s : 0.0}};
}

}  // namespace cohaptic
