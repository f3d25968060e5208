#pragma once
// The daemon's process shell: flags, signal handling, "radiantd listening on ..." line, graceful
// SIGTERM/SIGINT. Shared by radiantd (real renderer) and the test daemon (fake backend), so the
// process behaviour the HTTP tests check is exactly radiantd's.
#include <functional>

#include "server/Backend.h"
#include "server/Config.h"

namespace radiant::server {

// Returns the process exit code: 0 after a signal-initiated graceful stop, 2 for bad flags,
// 1 when binding or listening fails.
int runDaemon(int argc, char** argv, const std::function<BackendHooks(const ServerConfig&)>& makeHooks);

}  // namespace radiant::server
