#include "server/server_recording.h"

#include <filesystem>

#include "proto/wire/vec3_convert.h"

namespace cohaptic {

record::InjectedDelays injected_delays(const ServeOptions& options) {
  record::InjectedDelays injected;
  injected.set_shift_delay_ms(options.shift.delay_ms);
  injected.set_jitter_ms(options.shift.jitter_ms);
  injected.set_loss(options.shift.loss);
  injected.set_reorder(options.shift.reorder);
  injected.set_seed(options.shift.seed);
  injected.set_step_nodes(static_cast<std::uint32_t>(options.step_nodes));
  injected.set_sim_rate_hz(options.sim_rate_hz);
  injected.set_condensation(options.naive_condensation ? "naive" : "incremental");
  return injected;
}

wire::Protocol wire_protocol(const ServeOptions& options) {
  return options.protocol == ServeProtocol::p1 ? wire::P1 : wire::P0;
}

record::SessionConfig server_session_config(const ServeOptions& options, const Model& model,
                                            const std::string& scene_yaml, std::uint64_t session,
                                            std::int64_t start_time_ns) {
  record::SessionConfig config;
  config.set_role("server");
  config.set_scene_name(model.scene.name);
  config.set_scene_yaml(scene_yaml);
  config.set_options(options.options_text);
  config.set_scene_file(std::filesystem::absolute(options.scene).string());
  config.set_patch_rings(static_cast<std::uint32_t>(model.scene.haptic.patch_rings));
  config.set_ir_f32(options.precision == IrPrecision::f32);
  config.set_session(session);
  config.set_protocol(wire_protocol(options));
  *config.mutable_injected() = injected_delays(options);
  config.set_start_time_ns(start_time_ns);
  return config;
}

record::SimulationStep simulation_step_record(std::int64_t time_ns, double simulation_time,
                                              const std::vector<ToolInput>& tools,
                                              const std::vector<bool>& used,
                                              const SceneSimulation& simulation,
                                              const StepReport& report, bool display_frame,
                                              const std::vector<record::ServerForce>& forces) {
  record::SimulationStep step;
  step.set_time_ns(time_ns);
  step.set_simulation_time(simulation_time);
  for (std::size_t slot = 0; slot < tools.size(); ++slot) {
    auto* tool = step.add_tools();
    tool->set_slot(static_cast<std::uint32_t>(slot));
    tool->set_known(used[slot]);
    wire::to_wire(tools[slot].position, tool->mutable_position());
    tool->set_sample_time_ns(tools[slot].sample_time_ns);
    tool->set_buttons(tools[slot].buttons);
  }
  step.set_rebuilt(report.rebuilt);
  for (int user = 0; user < simulation.user_count(); ++user)
    if (simulation.pressing(user)) step.add_pressing_slots(static_cast<std::uint32_t>(user));
  step.set_display_frame(display_frame);
  step.set_boundary_nodes(static_cast<std::uint32_t>(report.boundary_nodes));
  step.set_fractured_m2(report.fractured_m2);
  step.set_vaporised_m2(report.vaporised_m2);
  for (const record::ServerForce& force : forces) *step.add_forces() = force;
  return step;
}

}  // namespace cohaptic
