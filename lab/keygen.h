// `cohaptic-lab keygen FILE`: a new random session key file (mode 0600), the server's
// `--key-file`. `cohaptic-lab keygen --session-key FILE --participant K OUT`: participant
// K's key file, derived from it, for that participant's `cohaptic-client --key-file` (formats
// in proto/wire/session_key.h, derivation in proto/wire/traffic_keys.h). It lives with the
// offline tools because it is one: it opens no socket, and the keys belong to the session,
// not to the server or to a client.
#pragma once

#include "lab/lab_command.h"

namespace cohaptic {

LabCommand add_keygen_command(CLI::App& lab);

}  // namespace cohaptic
