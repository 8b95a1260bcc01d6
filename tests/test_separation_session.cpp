// The separating-tissue session end to end: a cohaptic-server process
// serving scenes/separation/two_layers.yaml and two cohaptic-client processes playing its
// scripted users on loopback (the forceps grasp the flap's rim and pull it up, then hold
// it; the laser tool cuts a groove across the middle, then grasps before it and pushes it
// open). Checked from the clients' recordings:
//   - both users feel the tissue (forces in contact, up to the tear's F_n = J_c l_n);
//   - every force a client output equals the offline evaluation of the IR it held, for the
//     positions and buttons it used, bit for bit (its own prediction of fracture and
//     vaporisation included);
//   - the server's separated state, as its IRs carried it, grew during the session: the
//     flap torn at its rim (fracture), the groove cut (the laser) and opened by the push;
//   - the server's report gives that area, fractured and vaporised (the laser's about the
//     groove, l_f L); its recording re-runs to the same area at every step, and replay's
//     summary and steps.csv give it.
#include <gtest/gtest.h>
#include <signal.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <map>

#include "common/ir/evaluate_force.h"
#include "proto/record/recording.h"
#include "proto/wire/ir_convert.h"
#include "support/csv_table.h"
#include "support/process.h"
#include "support/run_program.h"

namespace cohaptic {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;

const fs::path kSeparationScenes = fs::path(COHAPTIC_SOURCE_DIR) / "scenes" / "separation";

struct SeparationUserCheck {
  int ticks = 0, evaluated = 0, in_contact = 0;
  double peak_force = 0;
  std::vector<std::shared_ptr<const PreparedIR>> irs;  // in epoch order
};

// Re-evaluates every tick of a client's recording on the IR it held, each IR's state
// starting where the client started it (fresh from the IR), and compares bit for bit.
SeparationUserCheck check_separation_recording(const fs::path& file) {
  const record::Recording recording = record::read_recording(file);
  std::map<std::uint64_t, std::shared_ptr<const PreparedIR>> irs;
  for (const record::RecordedIr& recorded : recording.irs)
    irs[recorded.ir().epoch()] =
        std::make_shared<const PreparedIR>(prepare_ir(wire::from_wire(recorded.ir())));
  SeparationUserCheck check;
  for (const auto& [epoch, ir] : irs) check.irs.push_back(ir);
  std::map<std::uint64_t, EvaluationState> states;
  for (const record::HapticTick& tick : recording.ticks) {
    ++check.ticks;
    if (tick.ir_epoch() == 0 || !tick.own_valid()) continue;
    const auto ir = irs.find(tick.ir_epoch());
    if (ir == irs.end()) {
      ADD_FAILURE() << "IR " << tick.ir_epoch() << " was not recorded";
      break;
    }
    auto state = states.find(tick.ir_epoch());
    if (state == states.end())
      state = states.emplace(tick.ir_epoch(), make_evaluation_state(*ir->second)).first;
    const ForceSample offline = evaluate_force(
        *ir->second, state->second, wire::from_wire(tick.own()), {}, tick.dt(), tick.buttons());
    const Eigen::Vector3d evaluated = wire::from_wire(tick.evaluated());
    EXPECT_EQ(offline.force, evaluated) << file.filename() << " tick " << check.ticks;
    if (offline.force != evaluated) break;
    ++check.evaluated;
    if (offline.flags & kInContact) ++check.in_contact;
    check.peak_force = std::max(check.peak_force, evaluated.norm());
  }
  return check;
}

// Separated area of the triangles whose centroid satisfies `where` [m^2].
template <typename Where>
double separated_where(const SeparationIr& ir, const Where& where) {
  double area = 0;
  for (int t = 0; t < ir.patch->triangle_count(); ++t)
    if (where(ir.patch->centroids[static_cast<std::size_t>(t)]))
      area += ir.state.separated[static_cast<std::size_t>(t)] *
              ir.patch->areas[static_cast<std::size_t>(t)];
  return area;
}

TEST(SeparationSession, TwoUsersFeelTheTissueTearAndCutItAndEachClientEqualsItsIrs) {
  const fs::path dir = testing::scratch_directory("separation-session");
  auto server = std::make_unique<ChildProcess>(
      testing::server_program(),
      std::vector<std::string>{
          "--scene", (kSeparationScenes / "two_layers.yaml").string(), "--listen", "127.0.0.1:0",
          "--duration", "60", "--report", (dir / "server.json").string(), "--record",
          (dir / "server.mcap").string(), "--cache-dir", (dir / "cache").string()},
      dir / "server.log");
  ASSERT_TRUE(testing::wait_for_output(*server, "listening on")) << server->log_text();
  const int port = testing::listening_port(server->log_text());
  const auto client = [&](const std::string& user, int slot, const std::string& script) {
    return std::make_unique<ChildProcess>(
        testing::client_program(),
        std::vector<std::string>{"--server", fmt::format("127.0.0.1:{}", port), "--user", user,
                                 "--slot", std::to_string(slot), "--device",
                                 "script:" + (kSeparationScenes / "two_layers" / script).string(),
                                 "--record", (dir / (user + ".mcap")).string(), "--report",
                                 (dir / (user + ".json")).string()},
        dir / (user + ".log"));
  };
  const auto forceps = client("alice", 0, "surgeon_a.yaml");
  const auto fibre = client("bob", 1, "surgeon_b.yaml");
  ASSERT_EQ(forceps->wait(testing::kPatience), 0) << forceps->log_text();
  ASSERT_EQ(fibre->wait(testing::kPatience), 0) << fibre->log_text();
  server->signal(SIGINT);
  ASSERT_EQ(server->wait(testing::kPatience), 0) << server->log_text();

  const SeparationUserCheck alice = check_separation_recording(dir / "alice.mcap");
  const SeparationUserCheck bob = check_separation_recording(dir / "bob.mcap");
  std::printf("  alice: %d ticks, %d re-evaluated, %d in contact, peak %.3f N, %zu IRs\n",
              alice.ticks, alice.evaluated, alice.in_contact, alice.peak_force, alice.irs.size());
  std::printf("  bob: %d ticks, %d re-evaluated, %d in contact, peak %.3f N, %zu IRs\n", bob.ticks,
              bob.evaluated, bob.in_contact, bob.peak_force, bob.irs.size());
  for (const SeparationUserCheck* user : {&alice, &bob}) {
    EXPECT_GT(user->evaluated, 3000);
    EXPECT_GT(user->in_contact, 500);
    ASSERT_GE(user->irs.size(), 3u);
  }
  for (const char* user : {"alice", "bob"})
    EXPECT_EQ(
        nlohmann::json::parse(std::ifstream(dir / (std::string(user) + ".json")))["fades"]["count"],
        0)
        << user << ": the force faded while pushing";
  const double f_n = std::get<SeparationIr>(alice.irs.front()->ir.body).patch->normal_threshold;
  EXPECT_GT(alice.peak_force, 0.8 * f_n) << "the forceps' pull reached the tear";
  EXPECT_GT(bob.peak_force, 0.1);

  // The server's state, as each user's IRs carried it: never shrinking, and at the end the
  // rim torn, the groove cut and more separated than the groove alone.
  for (const SeparationUserCheck* user : {&alice, &bob})
    for (std::size_t i = 1; i < user->irs.size(); ++i)
      EXPECT_GE(std::get<SeparationIr>(user->irs[i]->ir.body).state.separated_area,
                std::get<SeparationIr>(user->irs[i - 1]->ir.body).state.separated_area);
  const SeparationUserCheck& later =
      alice.irs.back()->ir.simulation_time > bob.irs.back()->ir.simulation_time ? alice : bob;
  const auto& last = std::get<SeparationIr>(later.irs.back()->ir.body);
  const double rim = separated_where(last, [](const Eigen::Vector3d& c) { return c.x() < 0.006; });
  const double groove = separated_where(
      last, [](const Eigen::Vector3d& c) { return std::abs(c.x() - 0.0205) < 0.002; });
  const double cut_alone = last.patch->spot_diameter * 0.016;
  std::printf(
      "  server's separated area at the end: %.1f mm^2 (rim %.1f, groove's triangles %.1f; the cut "
      "alone %.1f)\n",
      last.state.separated_area * 1e6, rim * 1e6, groove * 1e6, cut_alone * 1e6);
  EXPECT_GT(rim, 1e-6) << "the flap did not tear at its rim";
  EXPECT_GT(groove, 0.9 * cut_alone) << "no laser groove";
  EXPECT_GT(last.state.separated_area, rim + cut_alone + 1e-6)
      << "the push did not open the groove";

  // The server's report gives the area separated by fracture and by the laser: together at
  // least what the last IR carried (the session may have gone on a few steps past it), the
  // laser's about the groove (the cut's strip, l_f L).
  const nlohmann::json separated =
      nlohmann::json::parse(std::ifstream(dir / "server.json"))["server"]["separated_area_mm2"];
  const double fractured = separated["fractured"].get<double>(),
               vaporised = separated["vaporised"].get<double>();
  std::printf("  server's report: fractured %.2f mm^2, vaporised %.2f mm^2\n", fractured,
              vaporised);
  EXPECT_GE(fractured + vaporised, last.state.separated_area * 1e6 - 1e-9);
  EXPECT_GT(fractured, rim * 1e6);
  EXPECT_NEAR(vaporised, cut_alone * 1e6, 0.25 * cut_alone * 1e6);
  EXPECT_FALSE(separated["groove_record_full"].get<bool>());

  // The server's recording re-runs to the same area at every step; its summary and its
  // steps.csv give it.
  const fs::path recording = dir / "server.mcap";
  const testing::ProgramRun verify =
      testing::run_program(COHAPTIC_LAB_EXE, "replay '" + recording.string() + "' --verify", true);
  EXPECT_EQ(verify.exit_code, 0) << verify.out;
  EXPECT_NE(verify.out.find("verify: identical"), std::string::npos) << verify.out;
  const testing::ProgramRun summary = testing::run_program(
      COHAPTIC_LAB_EXE,
      "replay '" + recording.string() + "' --export-csv '" + (dir / "csv").string() + "' --summary",
      true);
  EXPECT_NE(
      summary.out.find(fmt::format("{:.2f} fractured, {:.2f} vaporised", fractured, vaporised)),
      std::string::npos)
      << summary.out;
  const std::vector<testing::CsvRow> steps = testing::read_csv_table(dir / "csv" / "steps.csv");
  ASSERT_FALSE(steps.empty());
  EXPECT_NEAR(std::stod(steps.back().at("fractured_mm2")), fractured, 1e-6 * fractured);
  EXPECT_NEAR(std::stod(steps.back().at("vaporised_mm2")), vaporised, 1e-6 * vaporised);
  EXPECT_EQ(std::stod(steps.front().at("fractured_mm2")), 0);
}

}  // namespace
}  // namespace cohaptic
