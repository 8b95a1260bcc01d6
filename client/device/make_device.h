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
#include <string>
#include <vector>

#include "common/haptics/haptic_device.h"

namespace cohaptic {

std::unique_ptr<HapticDevice> make_device(const std::string& spec, double force_limit);

/// The accepted forms, one "kind:ARGS  what" line each, for --help texts and errors.
std::vector<std::string> device_spec_forms();

}  // namespace cohaptic
