#pragma once
// radiantd's HTTP server in-process over the fake backend (FakeBackend.h) on an ephemeral loopback
// port: what ServerCoreTest and SessionTest start for each test.
#include <chrono>
#include <memory>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>

#include "FakeBackend.h"
#include "server/Config.h"
#include "server/HttpServer.h"

namespace radiant::test {

struct TestServer {
  FakeControl control;
  std::unique_ptr<server::HttpServer> server;
  std::thread thread;
  int port = 0;

  explicit TestServer(server::ServerConfig config = {}) {
    config.port = 0;
    server = std::make_unique<server::HttpServer>(config, fakeHooks(control));
    port = server->bind();
    thread = std::thread([this] { server->run(); });
  }
  ~TestServer() { stop(); }
  void stop() {
    if (!server) return;
    control.open();
    server->shutdown();
    thread.join();
    server.reset();
  }
  httplib::Client client(int readTimeoutS = 20) const {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(readTimeoutS, 0);
    return c;
  }
  void waitReady() {
    auto c = client();
    for (int i = 0; i < 500; ++i) {
      auto r = c.Get("/v1/ready");
      if (r && r->status == 200) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL() << "not ready";
  }
};

}  // namespace radiant::test
