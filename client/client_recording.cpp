#include "client/client_recording.h"

#include "client/client_network.h"
#include "proto/wire/vec3_convert.h"

namespace cohaptic {

record::SessionConfig client_session_config(const std::string& user, const std::string& device,
                                            double force_limit, std::uint64_t session,
                                            const std::optional<WelcomeInfo>& welcome,
                                            std::int64_t start_time_ns) {
  record::SessionConfig config;
  config.set_role("client");
  config.set_user(user);
  config.set_device(device);
  config.set_force_limit(force_limit);
  config.set_session(session);
  config.set_start_time_ns(start_time_ns);
  if (welcome) {
    config.set_scene_name(welcome->scene_name);
    config.set_scene_yaml(welcome->scene_yaml);
    config.set_slot(static_cast<std::uint32_t>(welcome->slot));
    config.set_protocol(welcome->protocol == HapticProtocol::p1 ? wire::P1 : wire::P0);
  }
  return config;
}

record::HapticTick haptic_tick_record(const TickRecord& tick) {
  record::HapticTick record;
  record.set_time_ns(tick.time_ns);
  wire::to_wire(tick.own, record.mutable_own());
  for (int r = 0; r < tick.remote_count; ++r)
    wire::to_wire(tick.remotes[static_cast<std::size_t>(r)], record.add_remotes());
  wire::to_wire(tick.force, record.mutable_force());
  wire::to_wire(tick.evaluated, record.mutable_evaluated());
  record.set_ir_epoch(tick.ir_epoch);
  record.set_dt(tick.dt);
  record.set_flags(tick.flags);
  record.set_fade(tick.fade);
  record.set_own_valid(tick.own_valid);
  record.set_buttons(tick.buttons);
  if (tick.ir_age_ns >= 0) record.set_ir_age_ns(tick.ir_age_ns);
  record.set_protocol(tick.protocol == HapticProtocol::p1 ? wire::P1 : wire::P0);
  return record;
}

}  // namespace cohaptic
