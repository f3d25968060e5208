#pragma once
// A small blocking HTTP client for the radiant CLI: base URL, optional bearer token, and the
// error model mapped to exceptions the CLI turns into exit codes.
#include <atomic>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace radiant::client {

// Exit codes of every subcommand.
enum ExitCode { kExitOk = 0, kExitUsage = 2, kExitServerError = 3, kExitUnreachable = 4 };

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct UnreachableError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// The server answered with an error: `problem` is its application/problem+json body (or a
// synthesised one when the body was something else).
struct ServerError : std::runtime_error {
  ServerError(int status, nlohmann::json problem);
  int status;
  nlohmann::json problem;
};

struct HttpResponse {
  int status = 0;
  std::string body;
  std::multimap<std::string, std::string> headers;  // lower-case names
  std::string header(const std::string& lowerName) const;
  nlohmann::json json() const;  // throws ServerError when the body is not JSON
};

// Extra request headers, by name.
using Headers = std::map<std::string, std::string>;

// The header a proxy in front of several daemons routes uploads, HEADs and renders on
// (docs/DEPLOYMENT.md): the scene's "sha256:..." digest, which the daemon checks against the scene.
inline constexpr const char* kSceneHeader = "X-Radiant-Scene";
inline Headers sceneHeader(const std::string& digest) { return digest.empty() ? Headers{} : Headers{{kSceneHeader, digest}}; }

// The last path segment of a problem+json answer's `type` ("queue-full"), or "" for another body.
std::string problemType(const HttpResponse& r);

// What a failed POST /v1/renders asks of a client behind a proxy in front of several daemons
// (docs/DEPLOYMENT.md). Again: the proxy lost the daemon on the way (502 daemon-unavailable, a
// daemon's 504) or the render reached a draining daemon (503 shutting-down); the proxy marks it down
// and the next try lands on another. Reupload: the render reached a daemon that inherited the scene's
// share of the hash but not the scene (404 unknown-scene). None: an answer to keep. Answers of a lone
// daemon (no X-Radiant-Daemon header, not the proxy's own 502) are always None.
enum class FleetRetry { None, Again, Reupload };
FleetRetry fleetRetry(const HttpResponse& r);

// A transport failure is an UnreachableError, with one exception: once an answer of this server carried
// X-Radiant-Daemon (a proxy in front of a fleet, or a daemon of one), an answer that breaks off after the
// request was sent (the connection closed mid-answer or timed out) is returned as the proxy's own
// 502 daemon-unavailable, detail "the answer broke off", so that fleetRetry sends the request again.
// nginx forwards a daemon's status line before its body; a daemon killed between the two leaves the
// client a truncated answer, not a 502. A lone daemon's broken answer stays an UnreachableError.
class HttpClient {
public:
  // baseUrl: "http://host:port" (no TLS: put a proxy in front). token: "" = no Authorization header.
  explicit HttpClient(std::string baseUrl, std::string token = "", int timeoutSeconds = 600);
  HttpResponse get(const std::string& path) const;
  HttpResponse head(const std::string& path, const Headers& extra = {}) const;
  HttpResponse del(const std::string& path) const;
  HttpResponse post(const std::string& path, const std::string& body, const std::string& contentType,
                    const Headers& extra = {}) const;
  HttpResponse put(const std::string& path, const std::string& body, const std::string& contentType,
                   const Headers& extra = {}) const;
  const std::string& baseUrl() const { return base_; }

  // Throws ServerError unless 200 <= status < 300.
  static const HttpResponse& expectOk(const HttpResponse& r);

private:
  HttpResponse send(const std::string& method, const std::string& path, const std::string* body,
                    const std::string& contentType, const Headers& extra = {}) const;
  std::string base_, token_;
  int timeout_;
  // Set by the first answer that carries X-Radiant-Daemon; shared by copies (the same server).
  std::shared_ptr<std::atomic<bool>> fleet_ = std::make_shared<std::atomic<bool>>(false);
};

}  // namespace radiant::client
