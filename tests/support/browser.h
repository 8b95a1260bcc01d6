// Headless Chromium for the tests that watch the live view in a real browser
// (tests/support/view_check.mjs, driven by playwright-core under Node.js).
#pragma once

#include <string>

namespace cohaptic::testing {

/// node, from the PATH; empty if there is none.
std::string node_program();

/// Why a browser cannot watch here (no node, no Chromium, no playwright-core), or empty.
/// deploy/install-deps.sh installs all three.
std::string missing_browser();

}  // namespace cohaptic::testing
