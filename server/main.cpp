// radiantd: the Radiant render daemon (docs/API.md). The real renderer behind the server core.
#include "server/Daemon.h"
#include "server/RendererBackend.h"

int main(int argc, char** argv) { return radiant::server::runDaemon(argc, argv, radiant::server::rendererHooks); }
