// `cohaptic-lab keygen FILE`: a new random session key file (mode 0600) for a server and
// its clients to share (`--key-file` on both; format in proto/wire/session_key.h). It lives
// with the offline tools because it is one: it opens no socket, and the key belongs to
// the session, not to the server or to a client.
#pragma once

#include "lab/lab_command.h"

namespace cohaptic {

LabCommand add_keygen_command(CLI::App& lab);

}  // namespace cohaptic
