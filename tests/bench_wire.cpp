// What sealing costs on the wire (docs/security.md "Security and robustness"): one tool-sample
// datagram and one IR frame, each sealed by the sender and opened by the receiver, in
// three modes side by side in one run:
//   none       serialize and parse only, no envelope and no tag: the cost without protection;
//   clear      the envelope and a Poly1305 tag over everything (--no-encryption);
//   encrypted  the envelope, XChaCha20 on the body and the tag (the default).
// The added cost of encryption is `encrypted` minus `none`. IRs are real ones from the
// paper's cube with two users and |B| held nodes (0, 150, 300), as the server sends them.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/sim/simulation.h"
#include "common/util/blas_threads.h"
#include "proto/wire/datagram_codec.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/sealer.h"
#include "proto/wire/traffic_keys.h"
#include "support/cube_scene.h"

namespace cohaptic {
namespace {

enum Mode : std::int64_t { none = 0, clear = 1, encrypted = 2 };
const char* const kModeNames[] = {"none", "clear", "encrypted"};

const wire::TrafficKey& key() {
  static const wire::TrafficKey k = wire::participant_key(wire::development_key(), 0);
  return k;
}

wire::Datagram tool_sample() {
  wire::Datagram d;
  d.mutable_tool()->set_user(0);
  d.mutable_tool()->set_sample_time_ns(123'456'789'012);
  d.mutable_tool()->mutable_position()->set_x(0.0123);
  d.mutable_tool()->mutable_position()->set_y(-0.0456);
  d.mutable_tool()->mutable_position()->set_z(-0.0021);
  d.mutable_tool()->set_valid(true);
  return d;
}

void BM_Datagram(benchmark::State& state, Mode mode) {
  wire::DatagramSealer sealer(key(), 42, 1, mode == encrypted);
  wire::DatagramInspector inspector(42, mode == clear);
  inspector.allow_sender(1, key(), sealer.salt());
  std::vector<std::uint8_t> bytes;
  std::size_t size = 0;
  wire::Datagram d = tool_sample();  // stamped anew each time, as a sender does
  for (auto _ : state) {
    if (mode == none) {
      sealer.stamp().stamp(*d.mutable_header());
      bytes.resize(d.ByteSizeLong());
      d.SerializeWithCachedSizesToArray(bytes.data());
      wire::Datagram parsed;
      if (!parsed.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())))
        state.SkipWithError("parse");
      benchmark::DoNotOptimize(parsed.tool().position().x());
    } else {
      bytes = sealer.seal(d);
      const std::optional<wire::Datagram> opened = inspector.inspect(bytes);
      if (!opened) state.SkipWithError("rejected");
      benchmark::DoNotOptimize(opened->tool().position().x());
    }
    size = bytes.size();
  }
  state.counters["bytes"] = static_cast<double>(size);
}

// A real IR of user 0 on the cube, two users pressing, |B| held nodes.
const wire::Control& ir_control(int held) {
  static std::map<int, wire::Control> irs;
  if (auto found = irs.find(held); found != irs.end()) return found->second;
  static const testing::CubeRig rig;
  SimulationOptions options;
  options.step_delay_nodes = held;
  Simulation simulation(rig.body, rig.model->obstacles, *rig.columns, std::vector<ToolSpec>(2),
                        options);
  simulation.set_tool(0, {0, 0, -0.002});
  simulation.set_tool(1, {0.03, 0, -0.002});
  simulation.step(0);
  wire::Control control;
  wire::to_wire(simulation.ir(0)->ir, control.mutable_ir());
  return irs.emplace(held, std::move(control)).first->second;
}

void BM_IrFrame(benchmark::State& state, Mode mode) {
  use_single_blas_thread();
  const wire::Control& ir = ir_control(static_cast<int>(state.range(0)));
  wire::FrameSealer sealer(key(), 42, wire::kServerSender, mode == encrypted);
  wire::FrameReader reader([](std::uint32_t) { return &key(); },
                           {.allow_cleartext = mode == clear});
  std::vector<std::uint8_t> bytes, received;
  std::size_t size = 0;
  wire::Control control = ir;  // stamped anew each time, as the server does
  for (auto _ : state) {
    if (mode == none) {  // serialize, carry over as the reader would (a copy), parse
      sealer.stamp().stamp(*control.mutable_header());
      bytes.resize(control.ByteSizeLong());
      control.SerializeWithCachedSizesToArray(bytes.data());
      received.assign(bytes.begin(), bytes.end());
      wire::Control parsed;
      if (!parsed.ParseFromArray(received.data(), static_cast<int>(received.size())))
        state.SkipWithError("parse");
      benchmark::DoNotOptimize(parsed.ir().fem().m_rows());
    } else {
      bytes = sealer.seal(control);
      reader.feed(bytes);
      const std::optional<wire::Control> opened = reader.next();
      if (!opened) state.SkipWithError("incomplete");
      benchmark::DoNotOptimize(opened->ir().fem().m_rows());
    }
    size = bytes.size();
  }
  state.counters["bytes"] = static_cast<double>(size);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(size));
}

void register_wire_benchmarks() {
  for (Mode mode : {none, clear, encrypted})
    benchmark::RegisterBenchmark((std::string("BM_Datagram/") + kModeNames[mode]).c_str(),
                                 [mode](benchmark::State& s) { BM_Datagram(s, mode); })
        ->Unit(benchmark::kMicrosecond);
  for (Mode mode : {none, clear, encrypted})
    benchmark::RegisterBenchmark((std::string("BM_IrFrame/") + kModeNames[mode]).c_str(),
                                 [mode](benchmark::State& s) { BM_IrFrame(s, mode); })
        ->Unit(benchmark::kMicrosecond)
        ->Arg(0)
        ->Arg(150)
        ->Arg(300);
}

const int wire_benchmarks_registered = (register_wire_benchmarks(), 0);

}  // namespace
}  // namespace cohaptic
