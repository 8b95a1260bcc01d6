#include "lab/keygen.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "common/util/error.h"
#include "proto/wire/session_key.h"

namespace cohaptic {
namespace {

struct KeygenOptions {
  std::filesystem::path file;
  std::filesystem::path session_key;
  std::optional<std::uint32_t> participant;
};

}  // namespace

LabCommand add_keygen_command(CLI::App& lab) {
  auto options = std::make_shared<KeygenOptions>();
  CLI::App* command = lab.add_subcommand("keygen",
                                         "Write a new random session key file, or with "
                                         "--participant K one participant's key file derived from "
                                         "the session key (mode 0600)");
  command->add_option("file", options->file, "Where to write it (it must not exist)")->required();
  command->add_option("--participant", options->participant,
                      "Write the key of slot K (from 0), derived from --session-key: give it to "
                      "that participant only");
  command
      ->add_option("--session-key", options->session_key,
                   "The session key file (with --participant)")
      ->check(CLI::ExistingFile);
  return {command, [options] {
            if (!options->participant) {
              if (!options->session_key.empty())
                throw Error("keygen: --session-key goes with --participant K");
              wire::write_session_key(options->file);
              spdlog::info("wrote a new session key to {}", options->file.string());
              return 0;
            }
            if (options->session_key.empty())
              throw Error("keygen --participant: the --session-key file is needed");
            wire::write_participant_key(options->file, wire::load_session_key(options->session_key),
                                        *options->participant);
            spdlog::info("wrote participant {}'s key to {}", *options->participant,
                         options->file.string());
            return 0;
          }};
}

}  // namespace cohaptic
