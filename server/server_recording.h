// What the server records of a session (--record FILE), through record::SessionRecorder
// (proto/record/session_recorder.h): the configuration first, then one SimulationStep
// per successful step, built here from what the simulation loop used and produced. The
// simulation thread records steps and IRs, the I/O thread datagrams and events (the
// recorder is thread-safe). `cohaptic-lab replay --verify` re-runs these steps.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cohaptic/recording.pb.h"
#include "common/model/model.h"
#include "common/sim/scene_simulation.h"
#include "server/serve_options.h"
#include "server/tool_inputs.h"

namespace cohaptic {

/// The injected delays and the step-delay settings, as recorded and as the live view shows them.
record::InjectedDelays injected_delays(const ServeOptions& options);
/// The protocol served, as on the wire.
wire::Protocol wire_protocol(const ServeOptions& options);

/// The first record: the role, the scene as served, the options and the injected delays.
record::SessionConfig server_session_config(const ServeOptions& options, const Model& model,
                                            const std::string& scene_yaml, std::uint64_t session,
                                            std::int64_t start_time_ns);

/// One step: the tool inputs (`used[slot]`: given to the simulation, fresh), whether it
/// rebuilt the IRs, who pressed, |B|, whether a display frame was solved after it, and the
/// P0 forces it sent.
record::SimulationStep simulation_step_record(std::int64_t time_ns, double simulation_time,
                                              const std::vector<ToolInput>& tools,
                                              const std::vector<bool>& used,
                                              const SceneSimulation& simulation,
                                              const StepReport& report, bool display_frame,
                                              const std::vector<record::ServerForce>& forces);

}  // namespace cohaptic
