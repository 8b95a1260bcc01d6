#include "server/simulation_loop.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "common/mesh/tet_mesh.h"
#include "common/separation/separation_state.h"
#include "common/sim/elastic_states.h"
#include "common/sim/ir_build_options.h"
#include "common/sim/loaded_columns.h"
#include "common/util/monotonic_clock.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/vec3_convert.h"
#include "server/server_recording.h"

namespace cohaptic {
namespace {

SimulationOptions simulation_options(const Model& model, const ServeOptions& options) {
  SimulationOptions sim;
  sim.ir = ir_build_options(model.scene.haptic);
  sim.ir.precision = options.precision;
  sim.step_delay_nodes = options.step_nodes;
  sim.naive_every_step = options.naive_condensation;
  return sim;
}

}  // namespace

SimulationLoop::SimulationLoop(const Model& model, std::span<ComplianceColumns* const> columns,
                               const ServeOptions& options, ToolInputs& tools,
                               LoopStatistics& statistics, DisplayWriter* display,
                               view::LiveView* view, record::SessionRecorder* recorder,
                               std::int64_t start_ns, ConditionSwitch* conditions)
    : options_(options),
      conditions_(conditions),
      protocol_(options.protocol),
      rate_hz_(options.sim_rate_hz > 0 ? options.sim_rate_hz : kDefaultSimulationRate_hz),
      tools_(tools),
      statistics_(statistics),
      display_(display),
      view_(view),
      recorder_(recorder),
      columns_(columns.begin(), columns.end()),
      start_ns_(start_ns),
      simulation_(model, columns, model.scene.tools, simulation_options(model, options)),
      view_forces_(static_cast<std::size_t>(simulation_.user_count()), Eigen::Vector3d::Zero()),
      model_(model),
      // Rows whenever asked, B truncation or not: a truncated IR lists the held nodes it leaves
      // out, and the client condenses over them too (common/ir/compliance_rows.h).
      compliance_rows_(options.compliance_rows),
      rows_senders_(static_cast<std::size_t>(simulation_.user_count())),
      rows_objects_(static_cast<std::size_t>(simulation_.user_count()), -1),
      stream_started_(static_cast<std::size_t>(simulation_.user_count()), 0),
      joins_seen_(static_cast<std::size_t>(simulation_.user_count()), 0),
      node_of_tag_(model.bodies.size()),
      encoder_(simulation_.user_count(), recorder, statistics) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (const auto* body = std::get_if<ElasticBody>(&model.bodies[i]))
      node_of_tag_[i] = node_indices_by_tag(body->mesh);
  for (std::size_t i = 0; i < model.bodies.size(); ++i)
    if (const auto* body = std::get_if<ElasticBody>(&model.bodies[i]); body && columns[i])
      prefetch_.push_back({columns[i], static_cast<int>(i),
                           std::make_unique<CompliancePrefetch>(*body, columns[i]->row_nodes())});
}

void SimulationLoop::deliver_prefetched() {
  for (BodyPrefetch& prefetch : prefetch_) prefetch.worker->deliver(*prefetch.columns);
}

Outbox SimulationLoop::step(std::int64_t now_ns) {
  StepOutput output = advance(now_ns);
  encoder_.encode(output.irs, output.outbox);
  return std::move(output.outbox);
}

std::optional<record::ConditionSwitch> SimulationLoop::apply_condition_switch(Outbox& outbox) {
  if (!conditions_) return std::nullopt;
  const ConditionSwitch::Served served = conditions_->served();
  if (served.switches == switches_applied_) return std::nullopt;
  switches_applied_ = served.switches;
  const ServedCondition& condition =
      conditions_->conditions()[static_cast<std::size_t>(served.index)];
  simulation_.set_step_delay_nodes(condition.step_nodes);
  outbox.link_delay = condition.link_delay(options_.shift);
  rate_hz_ = condition.sim_rate_hz > 0 ? condition.sim_rate_hz : kDefaultSimulationRate_hz;
  if (condition.protocol != protocol_) {
    protocol_ = condition.protocol;
    // To P1 the switch goes with the IRs sent again (advance()), in the encoder's outbox.
    if (protocol_ == ServeProtocol::p0) outbox.protocol_switch = wire::P0;
    resend_irs_ = protocol_ == ServeProtocol::p1;
  }
  spdlog::info("serving condition '{}' ({})", condition.name, condition.describe());
  record::ConditionSwitch recorded;
  recorded.set_name(condition.name);
  recorded.set_index(static_cast<std::uint32_t>(served.index));
  recorded.set_protocol(protocol_ == ServeProtocol::p1 ? wire::P1 : wire::P0);
  record::InjectedDelays& injected = *recorded.mutable_injected();
  injected = injected_delays(options_);  // reorder, seed and condensation: the session's
  injected.set_shift_delay_ms(condition.shift_delay_ms);
  injected.set_jitter_ms(condition.jitter_ms);
  injected.set_loss(condition.loss);
  injected.set_step_nodes(static_cast<std::uint32_t>(condition.step_nodes));
  injected.set_sim_rate_hz(condition.sim_rate_hz);
  return recorded;
}

SimulationLoop::StepOutput SimulationLoop::advance(std::int64_t now_ns) {
  StepOutput output;
  Outbox& outbox = output.outbox;
  const std::optional<record::ConditionSwitch> switched = apply_condition_switch(outbox);
  take_tools(now_ns);
  const StepReport report = simulation_.step(seconds_since_start(now_ns));
  if (report.groove_record_full && !told_groove_record_full_) {
    told_groove_record_full_ = true;
    spdlog::warn(
        "a separation body's groove record is full ({} segments): a laser pass over a groove cut "
        "from now on separates its area again",
        kGrooveSegmentCapacity);
  }
  const bool to_p1 = resend_irs_;
  if (report.rebuilt || resend_irs_) output.irs = new_irs(now_ns);
  if (to_p1) {  // told before the IRs on the same connection, or at once if there are none yet
    if (output.irs.empty())
      outbox.protocol_switch = wire::P1;
    else
      output.irs.front().announces_p1 = true;
  }
  if (protocol_ == ServeProtocol::p1 && now_ns - last_keep_alive_ns_ >= kKeepAlivePeriod_ns) {
    last_keep_alive_ns_ = now_ns;
    add_keep_alives(outbox);
  }
  const std::vector<record::ServerForce> forces =
      protocol_ == ServeProtocol::p0 ? add_forces(outbox) : std::vector<record::ServerForce>{};
  const bool display_frame = solve_display_frame(now_ns);
  if (recorder_) {
    record::SimulationStep step =
        simulation_step_record(now_ns, seconds_since_start(now_ns), latest_, used_, simulation_,
                               report, display_frame, forces);
    if (switched) *step.mutable_condition_switch() = *switched;
    recorder_->step(step);
    recorder_->flush_if_due();
  }
  ++steps_;
  const std::int64_t end_ns = monotonic_now_ns();
  statistics_.record_step({end_ns - now_ns, report, forces.size()}, seconds_since_start(end_ns));
  return output;
}

void SimulationLoop::take_tools(std::int64_t now_ns) {
  deliver_prefetched();
  for (int user : encoder_.take_restarts()) restart_rows(user);
  tools_.take(latest_);
  used_.assign(latest_.size(), false);
  const auto timeout = static_cast<std::int64_t>(options_.client_timeout_s * 1e9);
  for (std::size_t slot = 0; slot < latest_.size(); ++slot) {
    const ToolInput& tool = latest_[slot];
    if (slot < joins_seen_.size() && tool.joins != joins_seen_[slot]) {  // a new user holds no rows
      joins_seen_[slot] = tool.joins;
      restart_rows(static_cast<int>(slot));
    }
    used_[slot] = tool.joined && tool.valid && now_ns - tool.received_ns < timeout;
    if (conditions_ && options_.switch_button >= 0 && used_[slot] &&
        (tool.pressed & (1u << options_.switch_button)))
      conditions_->serve_next();
    if (used_[slot]) {
      simulation_.set_tool(static_cast<int>(slot), tool.position, tool.buttons);
      for (BodyPrefetch& prefetch : prefetch_)
        prefetch.worker->request_near(tool.position, *prefetch.columns);
    } else {
      simulation_.clear_tool(static_cast<int>(slot));
    }
  }
  for (BodyPrefetch& prefetch : prefetch_)  // as of the previous step
    prefetch.worker->request(
        std::get<Simulation>(simulation_.body(prefetch.body)).nodes_near_obstacles());
}

// The new IRs, to be recorded (either protocol) and sent to their users (P1).
std::vector<BuiltIr> SimulationLoop::new_irs(std::int64_t now_ns) {
  const bool send = protocol_ == ServeProtocol::p1;
  // After a switch to P1 every user's IR goes out, changed or not: its client changes over
  // with it (the IRs built under P0 were recorded, not sent).
  const bool every_user = std::exchange(resend_irs_, false);
  std::vector<BuiltIr> irs;
  if (!send && !recorder_) return irs;
  for (int user = 0; user < simulation_.user_count(); ++user) {
    auto prepared = simulation_.ir(user);
    if (!prepared || !(simulation_.ir_changed(user) || every_user)) continue;
    BuiltIr& built = irs.emplace_back();
    built.time_ns = now_ns;
    built.user = user;
    built.send = send;
    built.repeat = !simulation_.ir_changed(user);
    if (send) {
      // A sphere body's IR travels whole in the stream too (its normal compliance repeats
      // some of the last one's). Another condensed FEM body's may go as compliance rows.
      const auto* fem = std::get_if<CondensedFemIr>(&prepared->ir.body);
      const bool sphere = fem && fem->sphere;
      bool rows = false;
      if (!sphere) {
        IntermediateRepresentation as_rows = prepared->ir;
        if ((rows = to_compliance_rows(as_rows, user))) built.as_sent = std::move(as_rows);
      }
      built.streamed = rows || sphere;
      if (built.streamed) {  // the user's stream starts afresh with the rows or its first IR
        const auto u = static_cast<std::size_t>(user);
        built.fresh = rows ? condensed_fem(*built.as_sent).compliance_rows->generation == 1
                           : !stream_started_[u];
        stream_started_[u] = 1;
      }
    }
    built.built = std::move(prepared);
  }
  return irs;
}

bool SimulationLoop::to_compliance_rows(IntermediateRepresentation& ir, int user) {
  auto* fem = std::get_if<CondensedFemIr>(&ir.body);
  const auto object = static_cast<std::size_t>(ir.object);
  if (!compliance_rows_ || !fem || object >= columns_.size() || !columns_[object]) return false;
  // An FEM pair's front condenses over B folded in (supported_compliance.h): rows of its own
  // L would give the client A without B, and every held row changes with the pushing set,
  // so its M~ travels whole. The client keeps the rows it holds for the IRs after.
  if (simulation_.condenses_over_support(ir.object)) return false;
  const auto& body = std::get<ElasticBody>(model_.bodies[object]);
  ComplianceRowsSender& sender = rows_senders_[static_cast<std::size_t>(user)];
  // Node tags are per body: the user's IR moving to another body starts the client afresh.
  if (rows_objects_[static_cast<std::size_t>(user)] != ir.object) {
    rows_objects_[static_cast<std::size_t>(user)] = ir.object;
    restart_rows(user);
  }
  std::vector<int> mesh_nodes;
  for (const std::int64_t tag : fem->held_node_ids())
    mesh_nodes.push_back(node_of_tag_[object].at(tag));
  sender.convert(*fem, mesh_nodes, *columns_[object], body.dofs);
  return true;
}

void SimulationLoop::restart_rows(int user) {
  rows_senders_[static_cast<std::size_t>(user)].restart();
  stream_started_[static_cast<std::size_t>(user)] = 0;
}

void SimulationLoop::add_keep_alives(Outbox& outbox) {
  for (int user = 0; user < simulation_.user_count(); ++user) {
    const auto prepared = simulation_.ir(user);
    if (!prepared) continue;
    wire::Datagram datagram;
    auto* keep_alive = datagram.mutable_keep_alive();
    keep_alive->set_user(static_cast<std::uint32_t>(user));
    keep_alive->set_ir_epoch(prepared->ir.epoch);
    keep_alive->set_simulation_time(prepared->ir.simulation_time);
    outbox.datagrams.push_back({user, std::move(datagram)});
  }
}

// P0: each user's force, from its IR at the current tool positions; recorded with the step.
std::vector<record::ServerForce> SimulationLoop::add_forces(Outbox& outbox) {
  std::vector<record::ServerForce> forces;
  std::fill(view_forces_.begin(), view_forces_.end(), Eigen::Vector3d::Zero());
  for (int user = 0; user < simulation_.user_count(); ++user) {
    const auto prepared = simulation_.ir(user);
    if (!prepared) continue;
    const ForceSample force = simulation_.force(user);
    view_forces_[static_cast<std::size_t>(user)] = force.force;
    wire::Datagram datagram;
    auto* sample = datagram.mutable_force();
    sample->set_user(static_cast<std::uint32_t>(user));
    *sample->mutable_force() = wire::to_wire(force.force);
    sample->set_tool_time_ns(latest_[static_cast<std::size_t>(user)].sample_time_ns);
    sample->set_ir_epoch(prepared->ir.epoch);
    sample->set_flags(force.flags);
    record::ServerForce& recorded = forces.emplace_back();
    recorded.set_slot(static_cast<std::uint32_t>(user));
    wire::to_wire(force.force, recorded.mutable_force());
    recorded.set_ir_epoch(prepared->ir.epoch);
    recorded.set_flags(force.flags);
    outbox.datagrams.push_back({user, std::move(datagram)});
  }
  return forces;
}

bool SimulationLoop::solve_display_frame(std::int64_t now_ns) {
  const bool display_due =
      display_ &&
      now_ns - last_display_ns_ >= static_cast<std::int64_t>(1e9 / options_.display_rate_hz);
  const bool view_due = view_ && view_->frame_due(now_ns);
  if (!display_due && !view_due) return false;
  // One state solve per linear elastic body serves both (the replay solves them too).
  const std::vector<std::optional<StateSolution>> states = solve_elastic_states(simulation_);
  if (view_due) {
    view_tools_.resize(latest_.size());
    for (std::size_t slot = 0; slot < latest_.size(); ++slot)
      view_tools_[slot] = {used_[slot], latest_[slot].position};
    // The displacement and the encoding are the view's thread's work.
    view_->publish_frame(
        now_ns, seconds_since_start(now_ns),
        view::frame_state(simulation_, columns_, states, view_tools_, view_forces()), steps_);
  }
  if (!display_due) return true;
  if (const auto* tissue = std::get_if<HomeSpringSimulation>(&simulation_.body(0))) {
    // A home-spring tissue: its display deformation, decoupled from the force.
    offer_display_frame(now_ns, tissue->displayed() - tissue->body().surface.vertices);
    return true;
  }
  // Otherwise the display shows the row nodes' surface of a scene of one linear elastic
  // object (the server refuses it on another scene).
  offer_display_frame(
      now_ns, displacement_of_nodes(*columns_.front(), states.front().value(), display_->nodes()));
  return true;
}

const std::vector<Eigen::Vector3d>& SimulationLoop::view_forces() {
  if (protocol_ == ServeProtocol::p1)
    for (int user = 0; user < simulation_.user_count(); ++user)
      view_forces_[static_cast<std::size_t>(user)] = used_[static_cast<std::size_t>(user)]
                                                         ? simulation_.force(user).force
                                                         : Eigen::Vector3d::Zero();
  return view_forces_;
}

void SimulationLoop::offer_display_frame(std::int64_t now_ns, Eigen::Matrix3Xd displacement) {
  statistics_.record_display_frame(displacement.colwise().norm().maxCoeff());
  last_display_ns_ = now_ns;
  display_->offer(seconds_since_start(now_ns),
                  std::move(displacement));  // dropped if the writer is behind
}

std::optional<std::string> SimulationLoop::run(const std::atomic<bool>& running,
                                               const std::function<void(Outbox&&)>& send) {
  encoder_.start(send);
  const std::optional<std::string> failure = step_until(running, send);
  encoder_.stop();       // every IR built is recorded and handed over
  deliver_prefetched();  // so that the disk cache keeps them too
  return failure;
}

std::optional<std::string> SimulationLoop::step_until(const std::atomic<bool>& running,
                                                      const std::function<void(Outbox&&)>& send) {
  std::int64_t next = monotonic_now_ns();
  while (running.load()) {
    const std::int64_t step_start = monotonic_now_ns();
    try {
      StepOutput output = advance(step_start);
      failures_.succeeded();
      if (!output.irs.empty()) encoder_.post(std::move(output.irs));
      if (!output.outbox.empty()) send(std::move(output.outbox));
    } catch (const std::exception& e) {
      for (int user = 0; user < simulation_.user_count(); ++user) simulation_.clear_tool(user);
      const std::optional<std::string> line = failures_.failed(step_start, e.what());
      if (line) spdlog::error("{}", *line);
      statistics_.record_failure(failures_.consecutive(), e.what(),
                                 seconds_since_start(monotonic_now_ns()));
      if (failures_.limit_reached())
        return fmt::format("the simulation failed {} steps in a row, the last with: {}",
                           failures_.consecutive(), e.what());
    }
    next += static_cast<std::int64_t>(1e9 / rate_hz_);  // a switched condition may change the rate
    const std::int64_t step_end = monotonic_now_ns();
    if (next < step_end) next = step_end;  // behind: no catch-up burst
    std::this_thread::sleep_for(std::chrono::nanoseconds(next - step_end));
  }
  return std::nullopt;
}

}  // namespace cohaptic
