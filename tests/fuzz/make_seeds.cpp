// fuzz_make_seeds: writes the seed corpora of the wire and recording targets
// (corpus/{datagram,control_frames,ir,mcap,bridge,view}/) from real session recordings:
//   fuzz_make_seeds SERVER.mcap CLIENT.mcap MASS_SPRING_CLIENT.mcap SPHERE_CLIENT.mcap OUT_DIR
// make_seeds.sh records a short two-user session on the cube, a client's on the noodle
// (a mass-spring body, whose IRs carry a MassSpringPatch), and a client's pressing a sphere
// tool into the cube (the sphere contact model's IRs), and runs this on them. The
// file-format targets (scene, study, gmsh, freesurfer) take their seeds straight from the
// repository's files; make_seeds.sh copies those.
//
// Every seed is small: the smallest recorded IRs, a handful of datagrams, a recording of a
// few messages of each kind. Payloads are written unsealed, in the pieces layout of
// fuzz_support.h, so the seeds outlive a change of the wire's sealing.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "client/device/bridge_protocol.h"
#include "cohaptic/view.pb.h"
#include "common/ir/client_condensation.h"
#include "common/mesh/boundary_surface.h"
#include "common/mesh/read_gmsh.h"
#include "common/util/error.h"
#include "proto/record/mcap_writer.h"
#include "proto/record/recording.h"
#include "proto/record/session_recorder.h"
#include "proto/wire/frame_codec.h"
#include "proto/wire/header.h"
#include "proto/wire/ir_convert.h"
#include "proto/wire/ir_stream.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using namespace cohaptic;
namespace fs = std::filesystem;

constexpr std::uint8_t kSeal = 1;  // pieces' kind bit 0: the target seals the payload

std::vector<std::uint8_t> bytes_of(const google::protobuf::MessageLite& message) {
  const std::string s = message.SerializeAsString();
  return {s.begin(), s.end()};
}

void write_seed(const fs::path& directory, const std::string& name,
                const std::vector<std::uint8_t>& bytes) {
  fs::create_directories(directory);
  std::ofstream out(directory / name, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  std::printf("%s/%s: %zu bytes\n", directory.string().c_str(), name.c_str(), bytes.size());
}

std::vector<std::uint8_t> pieces(const std::vector<std::vector<std::uint8_t>>& payloads) {
  std::vector<std::uint8_t> input;
  for (const auto& payload : payloads) fuzz::append_piece(input, kSeal, payload);
  return input;
}

// The first datagram of each body kind in the recordings, in order of appearance.
std::map<int, wire::Datagram> one_of_each_kind(
    const std::vector<const record::Recording*>& recordings) {
  std::map<int, wire::Datagram> kinds;
  for (const record::Recording* recording : recordings)
    for (const record::ReceivedDatagram& received : recording->datagrams)
      kinds.emplace(static_cast<int>(received.datagram().body_case()), received.datagram());
  return kinds;
}

// The recorded IRs by size, smallest first, those sent as compliance rows completed as the
// client did (each stands alone then; rows_seed keeps one as it came).
std::vector<wire::IntermediateRepresentation> irs_by_size(
    const std::vector<const record::Recording*>& recordings) {
  std::vector<wire::IntermediateRepresentation> irs;
  for (const record::Recording* recording : recordings) {
    ClientCondensation client;
    for (const record::RecordedIr& recorded : recording->irs) {
      IntermediateRepresentation ir = wire::from_wire(recorded.ir());
      if (auto* fem = std::get_if<CondensedFemIr>(&ir.body)) client.complete(*fem);
      irs.push_back(wire::to_wire(ir));
    }
  }
  std::stable_sort(irs.begin(), irs.end(), [](const auto& a, const auto& b) {
    return a.ByteSizeLong() < b.ByteSizeLong();
  });
  return irs;
}

// A Welcome as the server would send it to the client that recorded `config`, with the
// surface of the two-tetrahedron test mesh (the cube's would make a 20 kB seed).
wire::Welcome welcome_for(const record::SessionConfig& config, const fs::path& source_dir) {
  wire::Welcome welcome;
  welcome.set_slot(config.slot());
  welcome.set_scene_name(config.scene_name());
  welcome.set_scene_yaml(config.scene_yaml());
  welcome.set_protocol(config.protocol());
  welcome.set_force_limit(config.force_limit());
  welcome.set_haptic_rate_hz(1000);
  welcome.set_server_udp_port(7400);
  welcome.set_ir_max_age_s(0.5);
  for (std::uint32_t slot = 0; slot < 2; ++slot) {
    wire::UserSlot* user = welcome.add_users();
    user->set_slot(slot);
    user->set_tool_name(slot == 0 ? "A" : "B");
    user->set_user_name(slot == config.slot() ? config.user() : "");
  }
  const TetMesh mesh = read_gmsh(source_dir / "tests/data/mesh_io/two_tets_v41.msh").mesh;
  const BoundarySurface surface = extract_boundary_surface(mesh);
  wire::SurfaceMesh* message = welcome.mutable_surface();
  for (int node : surface.nodes) {
    for (int axis = 0; axis < 3; ++axis) message->add_vertices(mesh.nodes(axis, node) * 1e-3);
    message->add_node_ids(mesh.node_tags[static_cast<std::size_t>(node)]);
  }
  for (const Triangle& triangle : surface.triangles)
    for (int node : triangle)
      message->add_triangles(static_cast<std::uint32_t>(
          std::lower_bound(surface.nodes.begin(), surface.nodes.end(), node) -
          surface.nodes.begin()));
  return welcome;
}

wire::Control control(std::uint64_t session, std::uint32_t sender, std::uint64_t sequence) {
  wire::Control message;
  wire::Header* header = message.mutable_header();
  header->set_protocol_version(wire::kProtocolVersion);
  header->set_session(session);
  header->set_sender(sender);
  header->set_sequence(sequence);
  header->set_sender_time_ns(1'000'000'000 + static_cast<std::int64_t>(sequence) * 1'000'000);
  return message;
}

void datagram_seeds(const std::vector<const record::Recording*>& recordings, const fs::path& out) {
  std::vector<std::vector<std::uint8_t>> all;
  for (const auto& [kind, datagram] : one_of_each_kind(recordings)) {
    write_seed(out, "kind_" + std::to_string(kind), pieces({bytes_of(datagram)}));
    all.push_back(bytes_of(datagram));
  }
  // A run of a client's datagrams as they arrived: several senders, increasing sequences.
  std::vector<std::vector<std::uint8_t>> run;
  for (const record::ReceivedDatagram& received : recordings.back()->datagrams) {
    if (run.size() == 24) break;
    run.push_back(bytes_of(received.datagram()));
  }
  write_seed(out, "client_run", pieces(run));
  // The same datagram twice: a replay.
  write_seed(out, "replayed", pieces({all.front(), all.front()}));
}

void control_seeds(const record::Recording& client,
                   const std::vector<wire::IntermediateRepresentation>& irs,
                   const wire::IntermediateRepresentation& mass_spring_ir,
                   const fs::path& source_dir, const fs::path& out) {
  const std::uint64_t session = client.config.session();
  const std::uint32_t server = wire::kServerSender;

  // A client holding the session key joins as the joining sender, with the greeting's challenge.
  wire::Control join = control(0, wire::kJoiningSender, 1);
  join.mutable_join()->set_user_name(client.config.user());
  join.mutable_join()->set_udp_port(40000);
  const wire::Challenge& challenge = fuzz::fuzz_challenge();
  join.mutable_join()->set_challenge(challenge.data(), challenge.size());
  join.mutable_join()->set_client_challenge(std::string(wire::kChallengeBytes, 'c'));
  join.mutable_join()->set_datagram_salt(fuzz::kFuzzSalt);
  write_seed(out, "join", pieces({bytes_of(join)}));

  wire::Control welcome = control(session, server, 1);
  *welcome.mutable_welcome() = welcome_for(client.config, source_dir);
  write_seed(out, "welcome", pieces({bytes_of(welcome)}));

  wire::Control ir = control(session, server, 2);
  *ir.mutable_ir() = irs.front();
  write_seed(out, "ir", pieces({bytes_of(ir)}));
  wire::Control patch = control(session, server, 2);
  *patch.mutable_ir() = mass_spring_ir;
  write_seed(out, "ir_mass_spring", pieces({bytes_of(patch)}));

  // Compressed IR blocks (proto/wire/ir_stream.h): a stream's first two, then one out of turn.
  wire::IrStreamWriter ir_stream;
  std::vector<std::vector<std::uint8_t>> compressed;
  for (std::uint64_t k = 0; k < 3; ++k) {
    wire::Control block = control(session, server, 2 + k);
    *block.mutable_compressed_ir() =
        ir_stream.compress(irs[std::min<std::size_t>(k, irs.size() - 1)], k == 0);
    if (k == 2) block.mutable_compressed_ir()->set_index(7);
    compressed.push_back(bytes_of(block));
  }
  write_seed(out, "ir_compressed_stream", pieces(compressed));

  std::vector<std::vector<std::uint8_t>> stream{bytes_of(welcome), bytes_of(ir)};
  std::uint64_t sequence = 3;
  for (const record::SessionEvent& recorded : client.events) {
    wire::Control event = control(session, server, sequence++);
    event.mutable_event()->set_kind(recorded.kind());
    event.mutable_event()->set_text(recorded.text());
    stream.push_back(bytes_of(event));
  }
  wire::Control bye = control(session, server, sequence);
  bye.mutable_bye()->set_reason("session over");
  stream.push_back(bytes_of(bye));
  write_seed(out, "server_stream", pieces(stream));

  // The same stream cut into reads of 7 bytes (kind bits 1..7 hold the read size - 1).
  std::vector<std::uint8_t> cut;
  for (const auto& payload : stream) fuzz::append_piece(cut, kSeal | (6u << 1), payload);
  write_seed(out, "server_stream_in_7_byte_reads", cut);

  wire::Control refusal = control(session, server, 1);
  refusal.mutable_error()->set_code("session_full");
  refusal.mutable_error()->set_text("no free user slot (the scene has 2 tools)");
  write_seed(out, "refusal", pieces({bytes_of(refusal)}));
}

void ir_seeds(const std::vector<wire::IntermediateRepresentation>& irs,
              const wire::IntermediateRepresentation& mass_spring_ir,
              const wire::IntermediateRepresentation& sphere_ir, const fs::path& out) {
  write_seed(out, "smallest", bytes_of(irs.front()));
  write_seed(out, "mass_spring", bytes_of(mass_spring_ir));
  write_seed(out, "sphere", bytes_of(sphere_ir));
  const auto with_remote = std::find_if(irs.begin(), irs.end(),
                                        [](const auto& ir) { return ir.fem().remotes_size() > 0; });
  if (with_remote != irs.end()) write_seed(out, "with_remote", bytes_of(*with_remote));
  // The smallest as a server with --ir-precision f32 sends it: M~ and u_B rounded to float.
  wire::IntermediateRepresentation f32 = irs.front();
  wire::CondensedFem& fem = *f32.mutable_fem();
  fem.clear_m_tilde_f64();
  fem.clear_boundary_displacement_f64();
  for (double v : irs.front().fem().m_tilde_f64()) fem.add_m_tilde_f32(static_cast<float>(v));
  for (double v : irs.front().fem().boundary_displacement_f64())
    fem.add_boundary_displacement_f32(static_cast<float>(v));
  write_seed(out, "smallest_f32", bytes_of(f32));
}

// The first IR a client took as compliance rows (generation 1: it stands alone), if any.
void rows_seed(const record::Recording& client, const fs::path& out) {
  for (const record::RecordedIr& recorded : client.irs)
    if (recorded.ir().has_fem() && recorded.ir().fem().rows_generation() == 1) {
      write_seed(out, "rows_first", bytes_of(recorded.ir()));
      return;
    }
}

// A complete recording of a few messages of each kind, and the same cut short as a killed
// writer leaves it.
void mcap_seeds(const record::Recording& server, const record::Recording& client,
                const fs::path& out) {
  fs::create_directories(out);
  const fs::path file = out / "short_session";
  {
    record::SessionRecorder recorder(file);
    recorder.config(client.config);
    for (std::size_t i = 0; i < std::min<std::size_t>(3, client.datagrams.size()); ++i)
      recorder.datagram_in(client.datagrams[i].receive_time_ns(), client.datagrams[i].datagram());
    const auto smallest = irs_by_size({&client});
    if (!smallest.empty()) recorder.ir(client.irs.front().time_ns(), smallest.front());
    for (std::size_t i = 0; i < std::min<std::size_t>(3, client.ticks.size()); ++i)
      recorder.tick(client.ticks[i]);
    for (std::size_t i = 0; i < std::min<std::size_t>(2, server.steps.size()); ++i)
      recorder.step(server.steps[i]);
    for (std::size_t i = 0; i < std::min<std::size_t>(2, client.events.size()); ++i)
      recorder.event(client.events[i].time_ns(), client.events[i].kind(), client.events[i].text());
    recorder.close();
  }
  std::printf("%s: %ju bytes\n", file.string().c_str(),
              static_cast<std::uintmax_t>(fs::file_size(file)));
  // The recorder embeds each channel's whole schema (55 kB of the above); this one names
  // its schema only, so the fuzzer's mutations land on the records around it.
  const fs::path small = out / "events_only";
  {
    record::McapWriter writer(small);
    const std::uint16_t schema =
        writer.add_schema(record::SessionEvent::descriptor()->full_name(), "protobuf", "");
    const std::uint16_t channel = writer.add_channel(schema, record::topic::kEvents);
    for (std::size_t i = 0; i < std::min<std::size_t>(3, client.events.size()); ++i) {
      const auto time = static_cast<std::uint64_t>(client.events[i].time_ns());
      writer.write(channel, static_cast<std::uint32_t>(i + 1), time, time, client.events[i]);
    }
    writer.close();
  }
  std::printf("%s: %ju bytes\n", small.string().c_str(),
              static_cast<std::uintmax_t>(fs::file_size(small)));
  std::ifstream in(file, std::ios::binary);
  std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                  std::istreambuf_iterator<char>()};
  bytes.resize(bytes.size() * 2 / 3);
  write_seed(out, "killed_writer", bytes);
}

// The view target's input: a recording of the live view (its scene, four frames while the
// users press, two status reports; schemas named only, as in the mcap seed events_only) as
// the first piece, then browsers' Commands, wall time passing and a handshake.
void view_seeds(const record::Recording& server, const fs::path& out) {
  if (server.view_scenes.empty() || server.view_frames.empty())
    throw Error("the server recording has no view frames (--view)");
  const fs::path file = out / "recording.mcap";
  fs::create_directories(out);
  {
    record::McapWriter writer(file);
    const auto channel = [&writer](const google::protobuf::Descriptor* descriptor,
                                   const char* topic) {
      return writer.add_channel(writer.add_schema(descriptor->full_name(), "protobuf", ""), topic);
    };
    const std::uint16_t config =
        channel(record::SessionConfig::descriptor(), record::topic::kConfig);
    const std::uint16_t scene = channel(view::Scene::descriptor(), record::topic::kViewScene);
    const std::uint16_t frames = channel(view::Frame::descriptor(), record::topic::kViewFrames);
    const std::uint16_t statuses =
        channel(record::ReceivedClientStatus::descriptor(), record::topic::kClientStatus);
    const auto start = static_cast<std::uint64_t>(server.config.start_time_ns());
    std::uint32_t sequence = 0;
    writer.write(config, ++sequence, start, start, server.config);
    writer.write(scene, ++sequence, start, start, server.view_scenes.front());
    const std::size_t count = std::min<std::size_t>(4, server.view_frames.size());
    const std::size_t first =
        (server.view_frames.size() - count) / 2;  // mid-session: while pressing
    for (std::size_t i = first; i < first + count; ++i) {
      const auto time = start + static_cast<std::uint64_t>(server.view_frames[i].time() * 1e9);
      writer.write(frames, ++sequence, time, time, server.view_frames[i]);
    }
    for (std::size_t i = 0; i < std::min<std::size_t>(2, server.client_statuses.size()); ++i) {
      const auto time = static_cast<std::uint64_t>(server.client_statuses[i].receive_time_ns());
      writer.write(statuses, ++sequence, time, time, server.client_statuses[i]);
    }
    writer.close();
  }
  std::ifstream in(file, std::ios::binary);
  const std::vector<std::uint8_t> recording{std::istreambuf_iterator<char>(in),
                                            std::istreambuf_iterator<char>()};
  fs::remove(file);
  if (recording.size() > 65535) throw Error("the view's seed recording exceeds a piece (64 kB)");

  const auto command_bytes = [](auto set) {
    view::Command command;
    set(command);
    return bytes_of(command);
  };
  std::vector<std::uint8_t> input;
  fuzz::append_piece(input, 0, recording);
  fuzz::append_piece(input, 0, command_bytes([](view::Command& c) { c.mutable_play(); }));
  const double half_second = 0.5;
  fuzz::append_piece(input, 1,
                     {reinterpret_cast<const std::uint8_t*>(&half_second), sizeof half_second});
  fuzz::append_piece(input, 0, command_bytes([](view::Command& c) { c.set_speed(4); }));
  fuzz::append_piece(input, 0, command_bytes([&server](view::Command& c) {
                       c.set_seek(server.view_frames.front().time());
                     }));
  fuzz::append_piece(
      input, 0, command_bytes([](view::Command& c) { c.set_jump(view::Command::PEAK_FORCE); }));
  fuzz::append_piece(input, 0, command_bytes([](view::Command& c) { c.mutable_pause(); }));
  const std::string handshake = "/ws?token=fuzz-token-0123456789";
  fuzz::append_piece(input, 2,
                     {reinterpret_cast<const std::uint8_t*>(handshake.data()), handshake.size()});
  write_seed(out, "replay_session", input);
}

void bridge_seeds(const record::Recording& client, const fs::path& out) {
  const auto pressing =
      std::find_if(client.ticks.begin(), client.ticks.end(),
                   [](const record::HapticTick& tick) { return tick.force().z() != 0; });
  const record::HapticTick& tick =
      pressing != client.ticks.end() ? *pressing : client.ticks.front();
  bridge::PosePacket pose;
  pose.sequence = 1234;
  pose.device_time_s = static_cast<double>(tick.time_ns()) * 1e-9;
  pose.position = {tick.own().x(), tick.own().y(), tick.own().z()};
  bridge::PoseBytes pose_bytes{};
  bridge::encode(pose, pose_bytes);
  write_seed(out, "pose", {pose_bytes.begin(), pose_bytes.end()});
  bridge::ForcePacket force;
  force.sequence = 1234;
  force.device_time_s = pose.device_time_s;
  force.force = {tick.force().x(), tick.force().y(), tick.force().z()};
  force.force_limit = client.config.force_limit();
  force.flags = bridge::kClientValid;
  bridge::ForceBytes force_bytes{};
  bridge::encode(force, force_bytes);
  write_seed(out, "force", {force_bytes.begin(), force_bytes.end()});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(
        stderr,
        "usage: %s SERVER.mcap CLIENT.mcap MASS_SPRING_CLIENT.mcap SPHERE_CLIENT.mcap OUT_DIR\n",
        argv[0]);
    return 2;
  }
  const record::Recording server = record::read_recording(argv[1]);
  const record::Recording client = record::read_recording(argv[2]);
  const record::Recording mass_spring_client = record::read_recording(argv[3]);
  const record::Recording sphere_client = record::read_recording(argv[4]);
  const fs::path out = argv[5];
  const std::vector<wire::IntermediateRepresentation> irs = irs_by_size({&server, &client});
  const std::vector<wire::IntermediateRepresentation> patches = irs_by_size({&mass_spring_client});
  const auto patch = std::find_if(patches.begin(), patches.end(),
                                  [](const auto& ir) { return ir.has_mass_spring(); });
  // The smallest sphere IR that holds a node: one whose contact solve has work to do.
  const std::vector<wire::IntermediateRepresentation> sphere_irs = irs_by_size({&sphere_client});
  const auto sphere = std::find_if(sphere_irs.begin(), sphere_irs.end(), [](const auto& ir) {
    return ir.has_fem() && ir.fem().contact_model() == wire::CondensedFem::SPHERE &&
           ir.fem().node_ids_size() > 0;
  });
  if (irs.empty() || client.datagrams.empty() || client.ticks.empty() || patch == patches.end() ||
      sphere == sphere_irs.end()) {
    std::fprintf(stderr,
                 "%s: the recordings hold no IRs of all three kinds, datagrams or haptic ticks\n",
                 argv[0]);
    return 1;
  }
  datagram_seeds({&server, &client}, out / "datagram");
  control_seeds(client, irs, *patch, COHAPTIC_SOURCE_DIR, out / "control_frames");
  ir_seeds(irs, *patch, *sphere, out / "ir");
  rows_seed(client, out / "ir");
  mcap_seeds(server, client, out / "mcap");
  bridge_seeds(client, out / "bridge");
  view_seeds(server, out / "view");
  return 0;
}
