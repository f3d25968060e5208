// radiantd's process shell (flags, signals, port line) around the fake backend: lets the process-level
// HTTP tests and the client tests run before the GL renderer exists, and without a GPU.
// FAKE_RENDER_DELAY_MS (environment) makes every render take that long.
#include <cstdlib>

#include "FakeBackend.h"
#include "server/Daemon.h"

int main(int argc, char** argv) {
  static radiant::test::FakeControl control;
  if (const char* d = std::getenv("FAKE_RENDER_DELAY_MS")) control.delayMs = std::atoi(d);
  return radiant::server::runDaemon(argc, argv,
                                    [](const radiant::server::ServerConfig&) { return radiant::test::fakeHooks(control); });
}
