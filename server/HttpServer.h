#pragma once
// radiantd's HTTP layer (cpp-httplib): routes, problem+json errors, auth, limits, per-request JSON
// log lines. Owns the scene store, frame store, metrics and the RenderService. Knows nothing of GL:
// everything renderer-specific comes in through BackendHooks.

#include <memory>
#include <string>

#include "server/Backend.h"
#include "server/Config.h"

namespace radiant::server {

class RenderService;

class HttpServer {
public:
  HttpServer(ServerConfig config, BackendHooks hooks);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds config.host:config.port (0 = ephemeral) and returns the port. Throws std::runtime_error.
  int bind();
  // Serves until shutdown() (or stop()). Returns false if the listener failed.
  bool run();
  // Graceful: new renders get 503, accepted ones finish, then the listener stops and run() returns.
  void shutdown();
  RenderService& service();
  const ServerConfig& config() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radiant::server
