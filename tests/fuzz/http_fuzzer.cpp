// libFuzzer: HTTP parsing, routing and problem writing of the server core (with the fake backend
// of the server tests). Each input is sent as raw bytes on a fresh loopback connection, whose write
// side is then closed; whatever comes back must be an HTTP/1.1 response, and a problem+json body
// must be valid JSON. ASan/UBSan watch the server's threads.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "FakeBackend.h"
#include "server/HttpServer.h"

namespace {

int gPort = 0;

void startServer() {
  static radiant::test::FakeControl control;
  radiant::server::ServerConfig config;
  config.port = 0;
  config.readTimeoutS = 0.5;
  config.keepAliveTimeoutS = 0.2;
  config.maxBodyBytes = 1u << 20;
  static auto server = std::make_unique<radiant::server::HttpServer>(config, radiant::test::fakeHooks(control));
  gPort = server->bind();
  std::thread([] { server->run(); }).detach();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  startServer();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(gPort));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  // The harness opens ~1700 connections a second, and each one it closes holds its ephemeral port in
  // TIME_WAIT for 60 s (the client's shutdown sends the first FIN). From one source address the port
  // range (~28k) ran out after a few minutes (connect failed in CI and here, 2026-12-04), so each
  // connection comes from the next of 250 loopback addresses (all of 127/8 is loopback on Linux): 7M
  // ports a minute. A connect that still fails (a full backlog on a loaded machine) is retried for 10 s
  // before it counts as the server having stopped listening, which is a bug.
  static std::uint32_t next = 0;
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_port = 0;
  int fd = -1;
  for (int attempt = 0;; ++attempt) {
    local.sin_addr.s_addr = htonl(0x7F000100u + 1 + (next++ % 250));  // 127.0.1.1 .. 127.0.1.250
    fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local) == 0 &&
        connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0)
      break;
    const int err = errno;
    if (fd >= 0) close(fd);
    if (attempt == 1000) {
      std::fprintf(stderr, "http_fuzzer: connect to the server failed for 10 s: %s\n", std::strerror(err));
      std::abort();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  timeval tv{2, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  send(fd, data, size, MSG_NOSIGNAL);
  shutdown(fd, SHUT_WR);
  std::string out;
  char buf[4096];
  ssize_t n;
  while ((n = recv(fd, buf, sizeof buf, 0)) > 0) out.append(buf, static_cast<std::size_t>(n));
  close(fd);
  if (out.empty()) return 0;  // httplib drops requests it cannot parse at all
  if (out.rfind("HTTP/1.1 ", 0) != 0) std::abort();
  const auto head = out.find("\r\n\r\n");
  if (out.find("application/problem+json") < head) {
    // Only a body that arrived whole (Content-Length) is checked; HEAD responses have none.
    const auto cl = out.find("Content-Length: ");
    if (cl < head) {
      const std::size_t len = std::strtoul(out.c_str() + cl + 16, nullptr, 10);
      if (out.size() - head - 4 == len && len > 0 &&
          nlohmann::json::parse(out.substr(head + 4), nullptr, false).is_discarded())
        std::abort();
    }
  }
  return 0;
}
