// `cohaptic-lab replay FILE`: looking at a recorded session, re-running it, exporting it.
//
//   --summary     what is in the recording (the default); of one cut short, how far its
//                 chunks' CRCs vouch for it
//   --verify      re-run the recorded inputs through the same computations and compare
//                 every force bit for bit:
//                   a client recording: each haptic tick's force from the IR it used (or the
//                   P0 force it held) and the positions it used, then faded and limited as
//                   the loop does;
//                   a server recording: the simulation re-run step by step from the recorded
//                   tool inputs (same model, same compliance), every IR it built and every
//                   P0 force it sent;
//                 exits non-zero and names the first difference; of a recording cut short
//                 it first says how far its chunks' CRCs vouch for it (describe_cut);
//   --export-csv  every kind of record as a CSV file in DIR;
//   --view        a server recording made with --view, in the live view's page with a
//                 timeline (lab/replay_view.h), until SIGINT.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "common/scene/scene_files.h"
#include "lab/lab_command.h"

namespace cohaptic {

struct ReplayOptions {
  std::filesystem::path file;
  bool summary = false;
  bool verify = false;
  std::filesystem::path export_csv;  ///< empty: no export
  std::string view;                  ///< HOST:PORT of the page; empty: none
  std::optional<std::filesystem::path> view_token_file;
  /// The folder a server recording's scene may read its files from, gmsh scripts included;
  /// nullopt: the recording's own folder, and no gmsh script.
  std::optional<std::filesystem::path> scene_dir;
};

/// Returns the process exit code: 0, or 1 if verification found a difference.
int run_replay(const ReplayOptions& options);

/// The outcome of verifying one recording.
struct VerifyResult {
  bool ok = true;
  std::size_t checked = 0;  ///< forces (and IRs) compared
  std::string first_difference;
};

/// Re-runs `file`. A server recording's scene reads its files as `scene_files` allows
/// (common/scene/scene_files.h); without it, from the recording's own folder only, and no
/// gmsh script: a recording may come from anyone (the command line without --scene-dir).
/// Throws cohaptic::Error naming the file if it cannot be read as a recording (a chunk
/// whose CRC does not match, for one) or not re-run.
VerifyResult verify_recording(const std::filesystem::path& file,
                              const SceneFileAccess& scene_files);
VerifyResult verify_recording(const std::filesystem::path& file);

/// `cohaptic-lab replay FILE [--summary|--verify|--export-csv DIR]`.
LabCommand add_replay_command(CLI::App& lab);

}  // namespace cohaptic
