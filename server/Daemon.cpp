#include "server/Daemon.h"

#include <csignal>
#include <cstdio>
#include <iostream>
#include <thread>

#include <pthread.h>
#include <unistd.h>

#include "server/HttpServer.h"

namespace radiant::server {

int runDaemon(int argc, char** argv, const std::function<BackendHooks(const ServerConfig&)>& makeHooks) {
  std::optional<ServerConfig> config;
  try {
    config = parseCommandLine(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::exception& e) {
    std::cerr << "radiantd: " << e.what() << "\n" << usage();
    return 2;
  }
  if (!config) return 0;

  // SIGTERM/SIGINT are taken by one thread with sigwait(); every other thread (HTTP workers, render
  // thread, encoders) inherits the blocked mask, so none is interrupted mid-call.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  try {
    HttpServer server(*config, makeHooks(*config));
    const int port = server.bind();
    std::printf("radiantd listening on http://%s:%d\n", config->host.c_str(), port);
    std::fflush(stdout);

    std::thread([&server, signals] {
      int sig = 0;
      sigwait(&signals, &sig);
      std::fprintf(stderr, "{\"event\":\"shutdown\",\"signal\":%d,\"detail\":\"finishing accepted renders\"}\n", sig);
      std::thread([&server] { server.shutdown(); }).detach();
      sigwait(&signals, &sig);  // a second signal: stop waiting for renders
      std::fprintf(stderr, "{\"event\":\"shutdown\",\"signal\":%d,\"detail\":\"forced\"}\n", sig);
      _exit(1);
    }).detach();

    if (!server.run()) {
      std::fprintf(stderr, "radiantd: the listener failed\n");
      return 1;
    }
    std::fprintf(stderr, "{\"event\":\"stopped\"}\n");
  } catch (const std::exception& e) {
    std::cerr << "radiantd: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace radiant::server
