// make_device: a HapticDevice from its command-line name.
//
//   script:FILE          ScriptedDevice playing the trajectory in FILE (trajectory.h)
//   hand:FILE            HandModelDevice tracking the trajectory in FILE as its reference,
//                        with the file's optional `hand:` parameters (hand_model.h)
//   bridge:PORT          BridgeDevice listening on 127.0.0.1:PORT (bridge_device.h)
//   bridge:HOST:PORT     BridgeDevice listening on HOST:PORT (an IP address; [v6]:PORT too)
//
// The device is built but not started (the caller calls start()). A spec of another form,
// an unreadable or invalid file, or a bad port throws Error (file problems: ParseError
// with file, line and key), the former listing the accepted forms. force_limit in N.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/haptics/haptic_device.h"
#include "common/haptics/trajectory.h"

namespace cohaptic {

std::unique_ptr<HapticDevice> make_device(const std::string& spec, double force_limit);

/// The path the device `spec` names will follow (script, hand: its trajectory, the hand
/// parameters checked too; replay: the recorded motion), or nullopt for a device a person
/// moves (bridge). Checks the spec and its file as make_device does, throwing the same
/// errors, without building the device: a client calls it before it joins.
std::optional<Trajectory> device_path(const std::string& spec);

/// The accepted forms, one "kind:ARGS  what" line each, for --help texts and errors.
std::vector<std::string> device_spec_forms();

}  // namespace cohaptic
