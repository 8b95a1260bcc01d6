#include "lab/keygen.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>

#include "proto/wire/session_key.h"

namespace cohaptic {

LabCommand add_keygen_command(CLI::App& lab) {
  auto file = std::make_shared<std::filesystem::path>();
  CLI::App* command = lab.add_subcommand("keygen", "Write a new random session key file (mode 0600)");
  command->add_option("file", *file, "Where to write it (it must not exist)")->required();
  return {command, [file] {
            wire::write_session_key(*file);
            spdlog::info("wrote a new session key to {}", file->string());
            return 0;
          }};
}

}  // namespace cohaptic
