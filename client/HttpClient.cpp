#include "client/HttpClient.h"

#include <algorithm>

#include <httplib.h>

namespace radiant::client {

std::string problemType(const HttpResponse& r) {
  const nlohmann::json problem = nlohmann::json::parse(r.body, nullptr, false);
  const std::string type = problem.is_object() ? problem.value("type", "") : "";
  return type.substr(type.rfind('/') == std::string::npos ? 0 : type.rfind('/') + 1);
}

FleetRetry fleetRetry(const HttpResponse& r) {
  if (r.status < 400) return FleetRetry::None;
  const std::string type = problemType(r);
  if (r.status == 502 && type == "daemon-unavailable") return FleetRetry::Again;  // the proxy's own answer
  if (r.header("x-radiant-daemon").empty()) return FleetRetry::None;               // a lone daemon
  if (r.status == 502 || r.status == 504 || (r.status == 503 && type == "shutting-down")) return FleetRetry::Again;
  if (r.status == 404 && type == "unknown-scene") return FleetRetry::Reupload;
  return FleetRetry::None;
}

ServerError::ServerError(int status, nlohmann::json problem)
    : std::runtime_error(problem.value("detail", "HTTP " + std::to_string(status))),
      status(status),
      problem(std::move(problem)) {}

std::string HttpResponse::header(const std::string& lowerName) const {
  auto it = headers.find(lowerName);
  return it == headers.end() ? "" : it->second;
}

nlohmann::json HttpResponse::json() const {
  auto j = nlohmann::json::parse(body, nullptr, false);
  if (j.is_discarded())
    throw ServerError(status, {{"title", "Unexpected response"}, {"status", status},
                               {"detail", "the server's answer is not JSON: " + body.substr(0, 200)}});
  return j;
}

HttpClient::HttpClient(std::string baseUrl, std::string token, int timeoutSeconds)
    : base_(std::move(baseUrl)), token_(std::move(token)), timeout_(timeoutSeconds) {
  while (!base_.empty() && base_.back() == '/') base_.pop_back();
  if (base_.rfind("http://", 0) != 0)
    throw UsageError("server URL must start with http:// (got \"" + base_ + "\"); TLS belongs to a proxy in front");
}

HttpResponse HttpClient::send(const std::string& method, const std::string& path, const std::string* body,
                              const std::string& contentType, const Headers& extra) const {
  httplib::Client cli(base_);
  cli.set_connection_timeout(5, 0);
  cli.set_read_timeout(timeout_, 0);
  cli.set_write_timeout(timeout_, 0);
  httplib::Headers headers;
  if (!token_.empty()) headers.emplace("Authorization", "Bearer " + token_);
  for (const auto& [k, v] : extra) headers.emplace(k, v);
  httplib::Result r = method == "GET"    ? cli.Get(path.c_str(), headers)
                      : method == "HEAD" ? cli.Head(path.c_str(), headers)
                      : method == "DELETE" ? cli.Delete(path.c_str(), headers)
                      : method == "POST" ? cli.Post(path.c_str(), headers, *body, contentType.c_str())
                                         : cli.Put(path.c_str(), headers, *body, contentType.c_str());
  if (!r && r.error() == httplib::Error::Read && fleet_->load()) {
    HttpResponse lost;
    lost.status = 502;
    lost.headers.emplace("content-type", "application/problem+json");
    lost.body = nlohmann::json{{"type", "https://radiant.dev/problems/daemon-unavailable"},
                               {"title", "Daemon unavailable"},
                               {"status", 502},
                               {"detail", "the answer to " + method + " " + path + " from " + base_ +
                                              " broke off mid-answer (its daemon went away); retry, or render again"}}
                    .dump();
    return lost;
  }
  if (!r)
    throw UnreachableError("cannot reach " + base_ + " (" + method + " " + path + "): " + httplib::to_string(r.error()));
  if (r->has_header("X-Radiant-Daemon")) fleet_->store(true);
  HttpResponse out;
  out.status = r->status;
  out.body = r->body;
  for (const auto& [k, v] : r->headers) {
    std::string lower = k;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    out.headers.emplace(lower, v);
  }
  return out;
}

HttpResponse HttpClient::get(const std::string& path) const { return send("GET", path, nullptr, ""); }
HttpResponse HttpClient::head(const std::string& path, const Headers& extra) const {
  return send("HEAD", path, nullptr, "", extra);
}
HttpResponse HttpClient::del(const std::string& path) const { return send("DELETE", path, nullptr, ""); }
HttpResponse HttpClient::post(const std::string& path, const std::string& body, const std::string& ct,
                              const Headers& extra) const {
  return send("POST", path, &body, ct, extra);
}
HttpResponse HttpClient::put(const std::string& path, const std::string& body, const std::string& ct,
                             const Headers& extra) const {
  return send("PUT", path, &body, ct, extra);
}

const HttpResponse& HttpClient::expectOk(const HttpResponse& r) {
  if (r.status >= 200 && r.status < 300) return r;
  auto j = nlohmann::json::parse(r.body, nullptr, false);
  if (!j.is_object() || !j.contains("detail"))
    j = {{"title", "HTTP " + std::to_string(r.status)}, {"status", r.status}, {"detail", r.body.substr(0, 500)}};
  throw ServerError(r.status, j);
}

}  // namespace radiant::client
