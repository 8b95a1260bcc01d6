// ServeOptions: everything `cohaptic-server --scene ... --listen ...` is told.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/ir/intermediate_representation.h"
#include "common/delay/link_delay.h"
#include "server/served_conditions.h"

namespace cohaptic {

struct ServeOptions {
  std::filesystem::path scene;
  std::string host = "127.0.0.1";
  std::uint16_t port = 7400;  ///< TCP and UDP; 0: any free port (tests)
  ServeProtocol protocol = ServeProtocol::p1;
  std::optional<std::filesystem::path>
      key_file;  ///< the session key; empty: the public development key
  bool encrypt =
      true;  ///< false: frames and datagrams in clear (still authenticated), and accepted so
  LinkDelaySettings shift;  ///< injected on every link, each direction
  int step_nodes = 0;       ///< step-delay boundary nodes (the paper's T150/T300)
  double sim_rate_hz = 0;   ///< cap of the simulation loop; 0: up to 1 kHz
  /// --condition: the conditions the session switches between (the first is served at the
  /// start, and protocol, shift delay, jitter, loss, step_nodes and sim_rate_hz above are
  /// its); empty: the one condition the options above give.
  std::vector<ServedCondition> conditions;
  std::optional<std::filesystem::path> control;  ///< --control: the control socket's path
  int switch_button = -1;  ///< --switch-button: a press of this device button (any user's) serves
                           ///< the next condition
  bool naive_condensation = false;  ///< rebuild M~ from scratch every step (the paper's loop)
  IrPrecision precision = IrPrecision::f64;
  /// Condensed FEM IRs as compliance rows (common/ir/compliance_rows.h; the client condenses),
  /// B truncation or not; false: M~ whole.
  bool compliance_rows = true;
  double duration_s = 0;          ///< 0: until SIGINT/SIGTERM
  std::filesystem::path report;   ///< JSON report at exit; empty: none
  double client_timeout_s = 0.5;  ///< no tool sample for this long: the tool is released
  double status_interval_s = 5;
  double ir_max_age_s = 0.5;  ///< told to clients: older IRs fade out
  std::optional<std::filesystem::path> cache_directory;
  std::filesystem::path record;  ///< MCAP recording of the session; empty: none
  std::string options_text;  ///< the command line options (CLI11 config format), for the recording
  std::filesystem::path display;  ///< deformed-surface frames (.vtu + .pvd) here; empty: none
  double display_rate_hz = 10;
  bool view = false;  ///< the live view in the browser (view/live_view.h)
  std::string view_host = "127.0.0.1";
  std::uint16_t view_port = 0;
  double view_rate_hz = 30;
  std::optional<std::filesystem::path>
      view_token_file;  ///< required off loopback; empty: a random token
};

}  // namespace cohaptic
