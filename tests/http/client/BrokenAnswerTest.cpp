// The client's HttpClient against a loopback server that writes raw HTTP: an answer that breaks off
// after its status line (what nginx forwards when the daemon behind it is killed between writing its
// headers and its body) is the proxy's 502 daemon-unavailable once this server has shown itself to be
// a fleet (an earlier answer carried X-Radiant-Daemon), so fleetRetry sends the render again; a lone
// server's broken answer stays a transport error (exit 4), and a refused connection always does.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "client/HttpClient.h"

namespace radiant::client {
namespace {

// Serves one connection per entry of `answers`, in order: reads the request (headers and a
// Content-Length body), writes the entry verbatim and closes.
class RawServer {
public:
  explicit RawServer(std::vector<std::string> answers) : answers_(std::move(answers)) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    EXPECT_EQ(bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(listen(fd_, 4), 0);
    socklen_t n = sizeof a;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] {
      for (const std::string& answer : answers_) {
        const int c = accept(fd_, nullptr, nullptr);
        if (c < 0) return;
        std::string request;
        char buf[4096];
        std::size_t end = std::string::npos;
        while (end == std::string::npos) {
          const ssize_t got = read(c, buf, sizeof buf);
          if (got <= 0) break;
          request.append(buf, static_cast<std::size_t>(got));
          end = request.find("\r\n\r\n");
        }
        std::size_t length = 0;
        if (const auto at = request.find("Content-Length: "); at != std::string::npos)
          length = std::stoul(request.substr(at + 16));
        while (end != std::string::npos && request.size() < end + 4 + length) {
          const ssize_t got = read(c, buf, sizeof buf);
          if (got <= 0) break;
          request.append(buf, static_cast<std::size_t>(got));
        }
        EXPECT_EQ(write(c, answer.data(), answer.size()), static_cast<ssize_t>(answer.size()));
        close(c);
      }
    });
  }
  ~RawServer() {
    thread_.join();
    close(fd_);
  }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }

private:
  std::vector<std::string> answers_;
  int fd_ = -1;
  int port_ = 0;
  std::thread thread_;
};

const std::string kFleetHead = "HTTP/1.1 200 OK\r\nX-Radiant-Daemon: d0\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
const std::string kLoneHead = "HTTP/1.1 200 OK\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
// A 202 whose body stops after 7 of its 64 bytes.
const std::string kBroken202 =
    "HTTP/1.1 202 Accepted\r\nContent-Type: application/json\r\nContent-Length: 64\r\nConnection: close\r\n\r\n{\"id\": ";

TEST(BrokenAnswer, BehindAFleetABrokenOffAnswerIsTheProxys502AndIsSentAgain) {
  RawServer server({kFleetHead, kBroken202});
  HttpClient http(server.url());
  ASSERT_EQ(http.head("/v1/scenes/x").status, 200);
  const HttpResponse r = http.post("/v1/renders", "{}", "application/json");
  EXPECT_EQ(r.status, 502);
  EXPECT_EQ(problemType(r), "daemon-unavailable");
  EXPECT_NE(r.json().value("detail", "").find("POST /v1/renders"), std::string::npos) << r.body;
  EXPECT_EQ(fleetRetry(r), FleetRetry::Again);
}

TEST(BrokenAnswer, ALoneServersBrokenOffAnswerStaysATransportError) {
  RawServer server({kLoneHead, kBroken202});
  HttpClient http(server.url());
  ASSERT_EQ(http.head("/v1/scenes/x").status, 200);
  EXPECT_THROW(http.post("/v1/renders", "{}", "application/json"), UnreachableError);
}

TEST(BrokenAnswer, ARefusedConnectionStaysATransportErrorEvenBehindAFleet) {
  std::unique_ptr<HttpClient> http;
  {
    RawServer server({kFleetHead});
    http = std::make_unique<HttpClient>(server.url());
    ASSERT_EQ(http->head("/v1/scenes/x").status, 200);
  }
  // The server is gone: nothing listens on its port, so no answer was begun.
  EXPECT_THROW(http->get("/v1/info"), UnreachableError);
}

}  // namespace
}  // namespace radiant::client
