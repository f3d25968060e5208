// The server core in-process, with the fake backend: routes, error model, queue, cancel, timeouts,
// scene store, metrics, shutdown. Talks real HTTP on an ephemeral loopback port.
#include <sys/stat.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <set>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "FakeBackend.h"
#include "TestServer.h"
#include "api/Sha256.h"
#include "server/Config.h"
#include "server/HttpServer.h"
#include "server/RenderService.h"

using nlohmann::json;
using radiant::server::HttpServer;
using radiant::server::ServerConfig;
using radiant::test::FakeControl;
using radiant::test::TestServer;

namespace {

json renderBody(std::uint64_t seed = 1, int w = 8, int h = 4) {
  return json{{"scene", {{"builtin", "tiny"}}}, {"width", w}, {"height", h}, {"seed", seed}};
}

httplib::Result post(httplib::Client& c, const std::string& path, const json& body) {
  return c.Post(path.c_str(), body.dump(), "application/json");
}

json body(const httplib::Result& r) { return json::parse(r->body); }

// GET /v1/renders/{id} until its state is `state` (at most 5 s); the last description.
json waitForState(httplib::Client& c, const std::string& id, const std::string& state) {
  json st;
  for (int i = 0; i < 500; ++i) {
    st = body(c.Get(("/v1/renders/" + id).c_str()));
    if (st["state"] == state) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return st;
}

// Every error response: problem+json with the given status, type slug and pointer.
void expectProblem(const httplib::Result& r, int status, const std::string& type, const std::string& pointer) {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << r->body;
  json p = json::parse(r->body, nullptr, false);
  ASSERT_TRUE(p.is_object()) << r->body;
  EXPECT_EQ(p["type"], "https://radiant.dev/problems/" + type) << r->body;
  EXPECT_EQ(p["status"], status);
  EXPECT_TRUE(p["title"].is_string());
  EXPECT_TRUE(p["detail"].is_string());
  EXPECT_TRUE(p["request_id"].is_string()) << r->body;
  EXPECT_EQ(p["request_id"], r->get_header_value("X-Request-Id"));
  if (pointer.empty()) EXPECT_FALSE(p.contains("pointer")) << r->body;
  else EXPECT_EQ(p.value("pointer", "<none>"), pointer) << r->body;
}

// The fake encoder writes "FAKEFRAME {json}".
json frameOf(const std::string& bytes) {
  EXPECT_EQ(bytes.rfind("FAKEFRAME ", 0), 0u) << bytes;
  return json::parse(bytes.substr(10));
}

void expectGoodRender(httplib::Client& c, std::uint64_t seed) {
  auto r = post(c, "/v1/renders", renderBody(seed));
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  json b = body(r);
  ASSERT_EQ(b["frames"].size(), 1u);
  auto f = c.Get(b["frames"][0]["url"].get<std::string>().c_str());
  ASSERT_TRUE(f);
  ASSERT_EQ(f->status, 200);
  EXPECT_DOUBLE_EQ(frameOf(f->body)["value"].get<double>(), double(seed) + 0.25);
}

std::filesystem::path tempDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("radiant-http-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace

TEST(ServerCore, HealthReadyInfo) {
  TestServer s;
  auto c = s.client();
  auto h = c.Get("/v1/health");
  ASSERT_TRUE(h);
  EXPECT_EQ(h->status, 200);
  EXPECT_EQ(body(h)["status"], "ok");
  s.waitReady();
  auto ready = c.Get("/v1/ready");
  EXPECT_EQ(body(ready)["device"]["renderer"], "fake");

  auto info = c.Get("/v1/info");
  ASSERT_EQ(info->status, 200);
  json i = body(info);
  EXPECT_EQ(i["name"], "radiantd");
  EXPECT_EQ(i["limits"]["max_width"], 4096);
  // The AOV table (api/Aovs.cpp): beauty accumulates into EXR's default layer; depth is one channel.
  std::map<std::string, json> aovs;
  for (const auto& a : i["aovs"]) aovs[a["name"].get<std::string>()] = a;
  EXPECT_EQ(aovs["beauty"]["blend"], "accumulate");
  EXPECT_EQ(aovs["beauty"]["channels"], json({"R", "G", "B"}));
  EXPECT_EQ(aovs["depth"]["channels"], json({"depth.Z"}));
  EXPECT_EQ(aovs["ao"]["format"], "R32F");
  EXPECT_EQ(aovs["specular"]["ground_truth"], nullptr);
  EXPECT_EQ(aovs["error"]["requestable"], false);
  bool sawDirect = false, sawReference = false;
  for (const auto& t : i["techniques"]) {
    if (t["name"] == "direct") {
      sawDirect = true;
      EXPECT_EQ(t["available"], true);
      EXPECT_EQ(t["params"]["pcf_radius"]["type"], "integer");
      EXPECT_EQ(t["params"]["pcf_radius"]["default"], 1);
      EXPECT_EQ(t["params"]["pcf_radius"]["maximum"], 4);
    }
    if (t["name"] == "reference") {
      sawReference = true;
      EXPECT_EQ(t["available"], false);  // the fake lists no reference technique
    }
  }
  EXPECT_TRUE(sawDirect);
  EXPECT_TRUE(sawReference);
  EXPECT_TRUE(i["request_schema"]["properties"]["passes"]["properties"].contains("direct"));
}

TEST(ServerCore, EveryErrorClassNamesItsFieldAndTheNextRequestWorks) {
  ServerConfig config;
  config.limits.maxWidth = 512;
  config.maxBodyBytes = 64 * 1024;
  TestServer s(config);
  s.waitReady();
  auto c = s.client();

  // 400: not JSON.
  expectProblem(c.Post("/v1/renders", "{\"scene\": ", "application/json"), 400, "malformed-json", "");
  expectGoodRender(c, 1);
  // 400: wrong JSON type.
  json b = renderBody();
  b["width"] = "wide";
  expectProblem(post(c, "/v1/renders", b), 400, "type-mismatch", "/width");
  expectGoodRender(c, 2);
  // 422: unknown key, deep.
  b = renderBody();
  b["passes"] = {{"direct", {{"pcf_radius", 1}, {"pcf_radios", 2}}}};
  expectProblem(post(c, "/v1/renders", b), 422, "unknown-field", "/passes/direct/pcf_radios");
  expectGoodRender(c, 3);
  // 422: out of range.
  b = renderBody();
  b["passes"] = {{"shadow_maps", {{"shadow_map_size", 100000}}}};
  expectProblem(post(c, "/v1/renders", b), 422, "out-of-range", "/passes/shadow_maps/shadow_map_size");
  expectGoodRender(c, 4);
  // 422: within the schema but above this server's limit.
  b = renderBody(1, 1024, 8);
  expectProblem(post(c, "/v1/renders", b), 422, "limit-exceeded", "/width");
  // 422: a technique the schema knows but this backend does not implement.
  b = renderBody();
  b["passes"] = {{"reference", json::object()}};
  expectProblem(post(c, "/v1/renders", b), 422, "technique-unavailable", "/passes/reference");
  // 422: an AOV no pass produced (found while encoding).
  b = renderBody();
  b["outputs"] = {{{"format", "exr"}, {"aovs", {"beauty", "albedo"}}}};
  expectProblem(post(c, "/v1/renders", b), 422, "aov-not-produced", "/outputs/0/aovs/1");
  expectGoodRender(c, 5);
  // 404: unknown scenes.
  b = renderBody();
  b["scene"] = {{"digest", "sha256:" + std::string(64, '0')}};
  expectProblem(post(c, "/v1/renders", b), 404, "unknown-scene", "/scene/digest");
  b["scene"] = {{"builtin", "nope"}};
  expectProblem(post(c, "/v1/renders", b), 404, "unknown-scene", "/scene/builtin");
  expectGoodRender(c, 6);
  // 413: body over the limit (httplib's own check via Content-Length, and ours).
  std::string big(100 * 1024, ' ');
  expectProblem(c.Post("/v1/renders", big, "application/json"), 413, "payload-too-large", "");
  expectProblem(c.Put("/v1/scenes", big, "model/gltf+json"), 413, "payload-too-large", "");
  expectGoodRender(c, 7);
  // 415: wrong content type.
  expectProblem(c.Post("/v1/renders", renderBody().dump(), "text/plain"), 415, "unsupported-media-type", "");
  expectProblem(c.Put("/v1/scenes", radiant::test::kTinyGltf, "image/png"), 415, "unsupported-media-type", "");
  expectGoodRender(c, 8);
  // 422: an invalid scene upload.
  expectProblem(c.Put("/v1/scenes", "{\"no\":\"asset\"}", "model/gltf+json"), 422, "invalid-scene", "");
  // 404: no such route, no such render, no such frame: still problem+json.
  expectProblem(c.Get("/v1/nothing"), 404, "not-found", "");
  expectProblem(c.Get("/v1/renders/r-doesnotexist"), 404, "unknown-render", "");
  expectProblem(c.Get("/v1/frames/r-x/0.png"), 404, "unknown-frame", "");
  // 422 raised by the renderer itself keeps its pointer.
  s.control.apiErrorNext = true;
  expectProblem(post(c, "/v1/renders", renderBody()), 422, "unknown-receiver", "/passes/direct");
  expectGoodRender(c, 9);
  EXPECT_EQ(s.control.creates, 1) << "a request error must not recreate the backend";
  // 500: an environment failure; the problem carries the render id, the backend is recreated.
  s.control.failNext = true;
  auto failed = post(c, "/v1/renders", renderBody());
  expectProblem(failed, 500, "render-failed", "");
  EXPECT_TRUE(body(failed)["render_id"].is_string());
  EXPECT_NE(body(failed)["detail"].get<std::string>().find("GL_OUT_OF_MEMORY"), std::string::npos);
  expectGoodRender(c, 10);
  EXPECT_EQ(s.control.creates, 2) << "the backend is recreated after an environment failure";
}

TEST(ServerCore, ClientRequestIdIsEchoed) {
  TestServer s;
  auto c = s.client();
  auto r = c.Get("/v1/health", {{"X-Request-Id", "trace-123"}});
  EXPECT_EQ(r->get_header_value("X-Request-Id"), "trace-123");
  r = c.Get("/v1/health", {{"X-Request-Id", "bad id with spaces"}});
  EXPECT_NE(r->get_header_value("X-Request-Id"), "bad id with spaces");
  EXPECT_FALSE(r->get_header_value("X-Request-Id").empty());
}

TEST(ServerCore, FullQueueIs503WithRetryAfter) {
  ServerConfig config;
  config.maxQueue = 2;
  TestServer s(config);
  s.waitReady();
  auto c = s.client();
  s.control.close();
  json a = renderBody(1);
  a["async"] = true;
  auto first = post(c, "/v1/renders", a);
  ASSERT_EQ(first->status, 202) << first->body;
  ASSERT_TRUE(s.control.waitStarted(1));  // running: not counted against the queue
  EXPECT_EQ(post(c, "/v1/renders", a)->status, 202);
  EXPECT_EQ(post(c, "/v1/renders", a)->status, 202);
  auto full = post(c, "/v1/renders", a);
  expectProblem(full, 503, "queue-full", "");
  ASSERT_TRUE(full->has_header("Retry-After"));
  EXPECT_GE(std::stoi(full->get_header_value("Retry-After")), 1);
  auto metrics = c.Get("/metrics");
  EXPECT_NE(metrics->body.find("radiant_queue_depth 2"), std::string::npos) << metrics->body;
  s.control.open();
  // Once the queue drains, a sync request goes through. (Wait for the drain: posting at once races
  // the render thread, which may not have taken the queued jobs yet.)
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (c.Get("/metrics")->body.find("radiant_queue_depth 0\n") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  expectGoodRender(c, 77);
}

TEST(ServerCore, EightConcurrentClientsGetTheirOwnFrames) {
  TestServer s;
  s.waitReady();
  s.control.delayMs = 20;
  std::vector<std::future<std::string>> results;
  for (int i = 0; i < 8; ++i)
    results.push_back(std::async(std::launch::async, [&s, i]() -> std::string {
      auto c = s.client();
      json b = renderBody(100 + i, 16 + i, 8 + i);
      b["outputs"] = {{{"format", "png"}}, {{"format", "exr"}, {"aovs", {"beauty", "depth"}}}};
      auto r = post(c, "/v1/renders", b);
      if (!r || r->status != 200) return "render failed: " + (r ? r->body : std::string("no response"));
      json out = body(r);
      if (out["frames"].size() != 2) return "expected 2 frames";
      json png = frameOf(c.Get(out["frames"][0]["url"].get<std::string>().c_str())->body);
      json exr = frameOf(c.Get(out["frames"][1]["url"].get<std::string>().c_str())->body);
      if (png["value"] != 100 + i + 0.25 || png["width"] != 16 + i || png["height"] != 8 + i || png["format"] != "png")
        return "wrong png frame " + png.dump();
      if (exr["aovs"] != json::array({"beauty", "depth"}) || exr["format"] != "exr") return "wrong exr frame " + exr.dump();
      return out["id"].get<std::string>();
    }));
  std::set<std::string> ids;
  for (auto& f : results) {
    std::string id = f.get();
    EXPECT_EQ(id.rfind("r-", 0), 0u) << id;
    ids.insert(id);
  }
  EXPECT_EQ(ids.size(), 8u);
  EXPECT_EQ(s.control.finished, 8);
}

TEST(ServerCore, AsyncProgressFollowsTheRenderer) {
  // The fake renderer reports half its frame done, then waits: the job shows 0.05 + 0.85 x 0.5.
  TestServer s;
  s.waitReady();
  s.control.close();
  auto c = s.client();
  json b = renderBody(6);
  b["async"] = true;
  auto r = post(c, "/v1/renders", b);
  ASSERT_EQ(r->status, 202);
  const std::string location = r->get_header_value("Location");
  json state;
  for (int i = 0; i < 500; ++i) {
    state = body(c.Get(location.c_str()));
    if (state["state"] == "running" && state["progress"].get<double>() > 0.05) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(state["phase"], "rendering");
  EXPECT_NEAR(state["progress"].get<double>(), 0.475, 1e-9);
  s.control.open();
  for (int i = 0; i < 500 && state["state"] != "done"; ++i) {
    state = body(c.Get(location.c_str()));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(state["progress"], 1.0);
}

// Polls an async job until it is done (or 5 s have passed); returns its last state.
json pollUntilDone(httplib::Client& c, const std::string& location) {
  json state = json::object();
  for (int i = 0; i < 1000 && state.value("state", "") != "done"; ++i) {
    state = body(c.Get(location.c_str()));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return state;
}

// Progressive refinement over the fake backend, whose beauty is seed + 0.25 everywhere: batches with
// seeds s, s+1, ..., s+n-1 average to s + (n-1)/2 + 0.25, and their sample variance (n(n+1)/12) gives the
// standard error of the mean sqrt((n+1)/12) in closed form.
TEST(ServerCore, RefineAveragesBatchesAndEstimatesTheStandardError) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  json b = renderBody(10);
  b["async"] = true;
  b["refine"] = {{"max_batches", 4}};
  auto r = post(c, "/v1/renders", b);
  ASSERT_EQ(r->status, 202) << r->body;
  const std::string location = r->get_header_value("Location");
  json state = pollUntilDone(c, location);
  ASSERT_EQ(state["state"], "done") << state.dump();
  const json& f = state["stats"]["refinement"];
  EXPECT_EQ(f["batches"], 4);
  EXPECT_EQ(f["stopped_by"], "max_batches");
  EXPECT_NEAR(f["estimated_rmse"].get<double>(), std::sqrt(5.0 / 12.0), 1e-6);
  EXPECT_EQ(f["seeds"], json::array({10, 13}));
  // The job's frame is the mean, and ?current=exr serves it with its estimate.
  const std::string frame = c.Get(state["frames"][0]["url"].get<std::string>().c_str())->body;
  EXPECT_NEAR(json::parse(frame.substr(frame.find('{')))["value"].get<double>(), 10 + 1.5 + 0.25, 1e-5);
  auto cur = c.Get((location + "?current=exr").c_str());
  ASSERT_EQ(cur->status, 200) << cur->body;
  EXPECT_EQ(cur->get_header_value("X-Radiant-Batches"), "4");
  EXPECT_NEAR(std::stod(cur->get_header_value("X-Radiant-Estimated-Rmse")), std::sqrt(5.0 / 12.0), 1e-5);
  EXPECT_NEAR(json::parse(cur->body.substr(cur->body.find('{')))["value"].get<double>(), 11.75, 1e-5);
  expectProblem(c.Get((location + "?current=tiff").c_str()), 400, "invalid-query", "");

  // A target error ends it early: after n batches the estimate is sqrt((n+1)/12), 0.5 at n = 2.
  b["refine"] = {{"max_batches", 50}, {"target_rmse", 0.51}};
  r = post(c, "/v1/renders", b);
  state = pollUntilDone(c, r->get_header_value("Location"));
  EXPECT_EQ(state["stats"]["refinement"]["batches"], 2);
  EXPECT_EQ(state["stats"]["refinement"]["stopped_by"], "target_rmse");

  // Not refining: no current frame; refine without async: 422 naming /refine.
  json plain = renderBody(3);
  plain["async"] = true;
  r = post(c, "/v1/renders", plain);
  expectProblem(c.Get((r->get_header_value("Location") + "?current=exr").c_str()), 409, "no-current-frame", "");
  json sync = renderBody(3);
  sync["refine"] = json::object();
  expectProblem(post(c, "/v1/renders", sync), 422, "invalid-value", "/refine");
}

TEST(ServerCore, AsyncRenderPollsToDone) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  json b = renderBody(5);
  b["async"] = true;
  auto r = post(c, "/v1/renders", b);
  ASSERT_EQ(r->status, 202);
  const std::string location = r->get_header_value("Location");
  EXPECT_EQ(location, "/v1/renders/" + body(r)["id"].get<std::string>());
  json state;
  for (int i = 0; i < 500; ++i) {
    state = body(c.Get(location.c_str()));
    if (state["state"] == "done") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(state["state"], "done") << state.dump();
  EXPECT_EQ(state["progress"], 1.0);
  EXPECT_EQ(state["stats"]["passes"][0]["name"], "fake_pass");
  EXPECT_EQ(state["stats"]["triangles"], std::string(radiant::test::kTinyGltf).size());
  auto f = c.Get(state["frames"][0]["url"].get<std::string>().c_str());
  EXPECT_EQ(frameOf(f->body)["value"], 5.25);
  EXPECT_EQ(f->get_header_value("Content-Type"), "image/png");
}

TEST(ServerCore, CancelQueuedRemovesItAndCancelRunningStopsIt) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  s.control.close();
  json b = renderBody(1);
  b["async"] = true;
  std::string running = body(post(c, "/v1/renders", b))["id"];
  ASSERT_TRUE(s.control.waitStarted(1));
  std::string queued = body(post(c, "/v1/renders", b))["id"];
  json q = body(c.Get(("/v1/renders/" + queued).c_str()));
  EXPECT_EQ(q["state"], "queued");
  EXPECT_EQ(q["queue_position"], 0);

  auto del = c.Delete(("/v1/renders/" + queued).c_str());
  ASSERT_EQ(del->status, 200);
  EXPECT_EQ(body(del)["state"], "canceled");
  expectProblem(c.Get(("/v1/renders/" + queued).c_str()), 404, "unknown-render", "");

  del = c.Delete(("/v1/renders/" + running).c_str());
  ASSERT_EQ(del->status, 202);
  EXPECT_EQ(body(del)["cancel_requested"], true);
  const json st = waitForState(c, running, "canceled");
  EXPECT_EQ(st["state"], "canceled") << st.dump();
  EXPECT_EQ(s.control.started, 1) << "the canceled queued job never reached the renderer";
  s.control.open();
  expectGoodRender(c, 3);
}

TEST(ServerCore, UploadIsIdempotentAndHeadAnswers) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  const std::string scene = R"({"asset":{"version":"2.0"},"extras":{"upload":1}})";
  const std::string digest = radiant::api::sceneDigest(scene);

  EXPECT_EQ(c.Head(("/v1/scenes/" + digest).c_str())->status, 404);
  auto first = c.Put("/v1/scenes", scene, "model/gltf+json");
  ASSERT_EQ(first->status, 201) << first->body;
  EXPECT_EQ(body(first)["digest"], digest);
  EXPECT_EQ(first->get_header_value("Location"), "/v1/scenes/" + digest);
  auto again = c.Post("/v1/scenes", scene, "model/gltf+json");
  ASSERT_EQ(again->status, 200);
  EXPECT_EQ(body(again)["digest"], digest);
  EXPECT_EQ(body(again)["created"], false);
  EXPECT_EQ(c.Head(("/v1/scenes/" + digest).c_str())->status, 200);
  EXPECT_EQ(c.Get(("/v1/scenes/" + digest).c_str())->body, scene);
  EXPECT_EQ(c.Head("/v1/scenes/tiny")->status, 200);  // builtins by name
  EXPECT_EQ(c.Head("/v1/scenes/nope")->status, 404);

  json list = body(c.Get("/v1/scenes"));
  ASSERT_EQ(list["uploaded"].size(), 1u);
  EXPECT_EQ(list["uploaded"][0]["digest"], digest);
  EXPECT_EQ(list["uploaded"][0]["format"], "gltf");
  ASSERT_EQ(list["builtins"].size(), 2u);
  EXPECT_EQ(list["builtins"][0]["name"], "tiny");
  EXPECT_EQ(list["builtins"][0]["digest"], radiant::api::sceneDigest(radiant::test::kTinyGltf));

  json b = renderBody(4);
  b["scene"] = {{"digest", digest}};
  auto r = post(c, "/v1/renders", b);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["stats"]["triangles"], scene.size());
  // A builtin is addressable by its digest too.
  b["scene"] = {{"digest", radiant::api::sceneDigest(radiant::test::kTinyGltf)}};
  EXPECT_EQ(post(c, "/v1/renders", b)->status, 200);
}

TEST(ServerCore, InlineGlbIsDecodedAndStored) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  const std::string glb = std::string("glTF\x02\x00\x00\x00", 8) + "0123456789";
  static const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < glb.size(); i += 3) {
    unsigned n = (unsigned char)glb[i] << 16;
    if (i + 1 < glb.size()) n |= (unsigned char)glb[i + 1] << 8;
    if (i + 2 < glb.size()) n |= (unsigned char)glb[i + 2];
    b64 += kB64[(n >> 18) & 63];
    b64 += kB64[(n >> 12) & 63];
    b64 += i + 1 < glb.size() ? kB64[(n >> 6) & 63] : '=';
    b64 += i + 2 < glb.size() ? kB64[n & 63] : '=';
  }
  json b = renderBody(2);
  b["scene"] = {{"inline_glb", b64}};
  auto r = post(c, "/v1/renders", b);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["stats"]["triangles"], glb.size());
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(glb)).c_str())->status, 200);
  b["scene"] = {{"inline_glb", "not*base64"}};
  expectProblem(post(c, "/v1/renders", b), 422, "invalid-value", "/scene/inline_glb");
}

TEST(ServerCore, ContentStoreSurvivesRestart) {
  const auto dir = tempDir("restart");
  ServerConfig config;
  config.cacheDir = dir.string();
  const std::string scene = R"({"asset":{"version":"2.0"},"extras":{"persist":true}})";
  const std::string digest = radiant::api::sceneDigest(scene);
  {
    TestServer s(config);
    auto c = s.client();
    ASSERT_EQ(c.Put("/v1/scenes", scene, "model/gltf+json")->status, 201);
  }
  {
    TestServer s(config);
    s.waitReady();
    auto c = s.client();
    EXPECT_EQ(c.Head(("/v1/scenes/" + digest).c_str())->status, 200);
    EXPECT_EQ(c.Put("/v1/scenes", scene, "model/gltf+json")->status, 200) << "already stored";
    json b = renderBody(6);
    b["scene"] = {{"digest", digest}};
    auto r = post(c, "/v1/renders", b);
    ASSERT_EQ(r->status, 200) << r->body;
    EXPECT_EQ(body(r)["stats"]["triangles"], scene.size());
  }
  std::filesystem::remove_all(dir);
}

// Issue 30: the cache directory reads only the regular files it wrote, checks their size before
// reading and their digest on first use, HEAD included; anything else is a miss (404), never a hang.
TEST(ServerCore, ContentStoreRefusesTamperedCacheFilesAsMisses) {
  const auto dir = tempDir("tamper");
  ServerConfig config;
  config.cacheDir = dir.string();
  auto sceneOf = [](int i) { return R"({"asset":{"version":"2.0"},"extras":{"i":)" + std::to_string(i) + "}}"; };
  auto fileOf = [&](int i) { return dir / "scenes" / (radiant::api::sceneDigest(sceneOf(i)).substr(7) + ".gltf"); };
  auto head = [&](httplib::Client& c, int i) { return c.Head(("/v1/scenes/" + radiant::api::sceneDigest(sceneOf(i))).c_str())->status; };
  {
    TestServer s(config);
    auto c = s.client();
    for (int i = 1; i <= 4; ++i) ASSERT_EQ(c.Put("/v1/scenes", sceneOf(i), "model/gltf+json")->status, 201);
  }
  // Before the restart: scene 1 truncated (its recorded size is then the truncated one: the digest catches it).
  std::filesystem::resize_file(fileOf(1), 10);
  TestServer s(config);
  s.waitReady();
  auto c = s.client();
  // After the restart: scene 2 grows, scene 3 becomes a FIFO (a blocking open would hang the store).
  { std::ofstream(fileOf(2), std::ios::app) << std::string(4096, ' '); }
  std::filesystem::remove(fileOf(3));
  ASSERT_EQ(::mkfifo(fileOf(3).c_str(), 0600), 0);
  EXPECT_EQ(head(c, 1), 404) << "truncated: digest mismatch";
  EXPECT_EQ(head(c, 2), 404) << "grown: size changed";
  EXPECT_EQ(head(c, 3), 404) << "a FIFO: not a regular file";
  EXPECT_EQ(head(c, 4), 200) << "intact";
  EXPECT_FALSE(std::filesystem::exists(fileOf(1)));
  EXPECT_FALSE(std::filesystem::exists(fileOf(2)));
  EXPECT_TRUE(std::filesystem::is_fifo(fileOf(3))) << "not the store's file: left alone";
  // A file in images/ named by its own digest but not an image, under an image's or a scene's extension.
  const std::string json = sceneOf(5), hex = radiant::api::sceneDigest(json).substr(7);
  for (const char* ext : {".png", ".gltf"}) {
    std::filesystem::create_directories(dir / "images");
    { std::ofstream(dir / "images" / (hex + ext), std::ios::binary) << json; }
  }
  {
    TestServer again(config);
    again.waitReady();
    auto c2 = again.client();
    const auto r = c2.Get(("/v1/images/" + radiant::api::sceneDigest(json)).c_str());
    EXPECT_EQ(r->status, 404) << r->body;
    again.stop();
  }
  // A miss is a miss: the scene can be stored again and rendered.
  EXPECT_EQ(c.Put("/v1/scenes", sceneOf(1), "model/gltf+json")->status, 201);
  EXPECT_EQ(head(c, 1), 200);
  s.stop();
  std::filesystem::remove_all(dir);
}

TEST(ServerCore, ContentStoreEvictsLeastRecentlyUsed) {
  const auto dir = tempDir("lru");
  ServerConfig config;
  config.cacheDir = dir.string();
  config.maxSceneBytes = 2048;
  TestServer s(config);
  auto c = s.client();
  auto sceneOf = [](int i) {
    return R"({"asset":{"version":"2.0"},"extras":{"i":)" + std::to_string(i) + R"(,"pad":")" + std::string(700, 'x') + "\"}}";
  };
  ASSERT_EQ(c.Put("/v1/scenes", sceneOf(1), "model/gltf+json")->status, 201);
  ASSERT_EQ(c.Put("/v1/scenes", sceneOf(2), "model/gltf+json")->status, 201);
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(sceneOf(1))).c_str())->status, 200);  // 1 is now newer
  ASSERT_EQ(c.Put("/v1/scenes", sceneOf(3), "model/gltf+json")->status, 201);
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(sceneOf(2))).c_str())->status, 404) << "evicted";
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(sceneOf(1))).c_str())->status, 200);
  EXPECT_EQ(c.Head(("/v1/scenes/" + radiant::api::sceneDigest(sceneOf(3))).c_str())->status, 200);
  int files = 0;
  for (const auto& f : std::filesystem::directory_iterator(dir / "scenes")) files += f.is_regular_file();
  EXPECT_EQ(files, 2);
  s.stop();
  std::filesystem::remove_all(dir);
}

TEST(ServerCore, TimeoutFreesTheQueueSlot) {
  ServerConfig config;
  config.maxQueue = 1;
  config.requestTimeoutS = 0.5;
  TestServer s(config);
  s.waitReady();
  auto c = s.client();
  s.control.close();
  json b = renderBody(1);
  b["async"] = true;
  std::string running = body(post(c, "/v1/renders", b))["id"];
  ASSERT_TRUE(s.control.waitStarted(1));
  std::string queued = body(post(c, "/v1/renders", b))["id"];
  expectProblem(post(c, "/v1/renders", b), 503, "queue-full", "");
  // The timeout is 0.5 s; wait for the server's verdict rather than a fixed time, so that a loaded
  // machine (where the timer thread runs late) cannot fail the test.
  json q;
  for (int i = 0; i < 200; ++i) {
    q = body(c.Get(("/v1/renders/" + queued).c_str()));
    if (q["state"] == "failed") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(q["state"], "failed");
  EXPECT_EQ(q["error"]["status"], 504);
  json r = body(c.Get(("/v1/renders/" + running).c_str()));
  EXPECT_EQ(r["state"], "failed") << "the running job timed out too";
  // The slot is free again: a new job is accepted although the first is still on the render thread.
  auto next = post(c, "/v1/renders", b);
  EXPECT_EQ(next->status, 202) << next->body;
  // A synchronous request that times out answers 504. (Wait until `next` runs, so the queue is empty.)
  ASSERT_TRUE(s.control.waitStarted(2));
  b["async"] = false;
  auto sync = post(c, "/v1/renders", b);
  expectProblem(sync, 504, "timeout", "");
  s.control.open();
}

// Issue 30, memory admission by bytes: decodes in flight share --decode-memory-bytes (64 MiB here). A
// decode holding 48 MiB leaves room for a 1 MiB one at the same time, while one that needs 32 MiB more
// waits up to a second and gets 503 decode-busy with Retry-After; once the first ends it succeeds. One
// decode asking for more than the whole budget is refused at once. /metrics shows the bytes reserved
// and the refusals; /v1/info the effective budget (never below --max-decode-bytes).
// Issue 30, images decoded once: renders that name an image being decoded wait for that decode and
// share it (eight renders naming one new 4096 x 4096 map decoded it eight times at once, 2.5 GB).
TEST(ServerCore, RendersNamingOneImageShareItsDecode) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  // The upload decodes it once to check it (not kept decoded).
  const std::string exr = std::string("\x76\x2f\x31\x01", 4) + "hold-image";
  auto up = c.Put("/v1/images", exr, "image/x-exr");
  ASSERT_TRUE(up);
  ASSERT_EQ(up->status, 201) << up->body;
  const std::string digest = body(up)["digest"];
  ASSERT_EQ(s.control.imageDecodes.load(), 1);
  s.control.holdDecode = true;
  json b = renderBody();
  b["environment"] = digest;
  b["async"] = true;
  std::vector<std::thread> renders;
  std::atomic<int> accepted{0};
  for (int i = 0; i < 4; ++i)
    renders.emplace_back([&, i] {
      json mine = b;
      mine["seed"] = 100 + i;
      auto cc = s.client();
      auto r = post(cc, "/v1/renders", mine);
      if (r && r->status == 202) ++accepted;
      else ADD_FAILURE() << (r ? r->body : std::string("no response"));
    });
  for (int i = 0; i < 2000 && s.control.imageDecoding.load() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(s.control.imageDecoding.load(), 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the others reach the image meanwhile
  EXPECT_EQ(s.control.imageDecoding.load(), 1);
  EXPECT_EQ(s.control.imageDecodes.load(), 2);
  s.control.holdDecode = false;
  for (auto& t : renders) t.join();
  EXPECT_EQ(accepted.load(), 4);
  EXPECT_EQ(s.control.imageDecodes.load(), 2);
  auto metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("radiant_image_decodes_total 1\n"), std::string::npos) << metrics->body;
}

TEST(ServerCore, DecodesShareTheDecodeMemoryByBytes) {
  ServerConfig config;
  config.maxDecodeBytes = 64u << 20;
  config.decodeMemoryBytes = 64u << 20;
  TestServer s(config);
  s.waitReady();
  auto info = body(s.client().Get("/v1/info"));
  EXPECT_EQ(info["limits"]["decode_memory_effective_bytes"], 64u << 20);
  s.control.holdDecode = true;
  const std::string held = R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":48,"hold-decode":1}})";
  std::thread first([&] {
    auto c = s.client();
    auto r = c.Put("/v1/scenes", held, "model/gltf+json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 201) << r->body;
  });
  for (int i = 0; i < 2000 && s.control.decoding.load() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(s.control.decoding.load(), 1);
  auto c = s.client();
  auto metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("radiant_decode_bytes_reserved 50331648\n"), std::string::npos) << metrics->body;
  // A small decode runs beside the held one.
  const std::string small = R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":1,"n":1}})";
  auto fits = c.Put("/v1/scenes", small, "model/gltf+json");
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->status, 201) << fits->body;
  // One that does not fit beside it waits, then is refused.
  const std::string other = R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":32,"n":7}})";
  const auto t0 = std::chrono::steady_clock::now();
  auto busy = c.Put("/v1/scenes", other, "model/gltf+json");
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  expectProblem(busy, 503, "decode-busy", "");
  EXPECT_EQ(busy->get_header_value("Retry-After"), "1");
  EXPECT_GE(waited, 0.9);
  // More than the whole budget: refused without waiting for anything.
  const std::string huge = R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":65,"n":8}})";
  expectProblem(c.Put("/v1/scenes", huge, "model/gltf+json"), 503, "decode-busy", "");
  metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("radiant_decodes_refused 2\n"), std::string::npos) << metrics->body;
  s.control.holdDecode = false;
  first.join();
  metrics = c.Get("/metrics");
  EXPECT_NE(metrics->body.find("radiant_decode_bytes_reserved 0\n"), std::string::npos) << metrics->body;
  auto ok = c.Put("/v1/scenes", other, "model/gltf+json");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 201) << ok->body;
}

// Issue 30, request bodies bounded by bytes: the bodies being read or handled share --body-memory-bytes
// (1 MiB here, with --max-body-bytes 1 MiB). An upload of 600 KiB held in its decode keeps its body
// charged until it is answered; a second of 600 KiB waits a second and gets 503 body-busy with
// Retry-After, its connection closed (refused on its Content-Length, before its body is read); a small
// one fits beside; once the first is answered the second succeeds. Before, each HTTP thread could hold a
// body of --max-body-bytes (24 threads x 64 MiB by default).
TEST(ServerCore, RequestBodiesShareTheBodyMemoryByBytes) {
  ServerConfig config;
  config.maxBodyBytes = 1u << 20;
  config.bodyMemoryBytes = 1u << 20;
  TestServer s(config);
  s.waitReady();
  auto info = body(s.client().Get("/v1/info"));
  EXPECT_EQ(info["limits"]["body_memory_effective_bytes"], 1u << 20);
  auto padded = [](int n, bool hold) {
    return R"({"asset":{"version":"2.0"},"extras":{"n":)" + std::to_string(n) + (hold ? R"(,"hold-decode":1)" : "") +
           R"(,"pad":")" + std::string(600 << 10, 'x') + "\"}}";
  };
  const std::string held = padded(1, true);
  s.control.holdDecode = true;
  std::thread first([&] {
    auto c = s.client();
    auto r = c.Put("/v1/scenes", held, "model/gltf+json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 201) << r->body;
  });
  for (int i = 0; i < 2000 && s.control.decoding.load() == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(s.control.decoding.load(), 1);
  auto c = s.client();
  auto metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("radiant_body_bytes_reserved " + std::to_string(held.size()) + "\n"), std::string::npos)
      << metrics->body.substr(0, 200);
  // A small body fits beside the held one.
  const std::string small = R"({"asset":{"version":"2.0"},"extras":{"n":2}})";
  auto fits = c.Put("/v1/scenes", small, "model/gltf+json");
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->status, 201) << fits->body;
  // A second large one does not: it waits, then is refused.
  const std::string other = padded(3, false);
  auto c2 = s.client();
  const auto t0 = std::chrono::steady_clock::now();
  auto busy = c2.Put("/v1/scenes", other, "model/gltf+json");
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  expectProblem(busy, 503, "body-busy", "");
  EXPECT_EQ(busy->get_header_value("Retry-After"), "1");
  EXPECT_EQ(busy->get_header_value("Connection"), "close");
  EXPECT_GE(waited, 0.9);
  metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("radiant_bodies_refused 1\n"), std::string::npos);
  s.control.holdDecode = false;
  first.join();
  metrics = c.Get("/metrics");
  EXPECT_NE(metrics->body.find("radiant_body_bytes_reserved 0\n"), std::string::npos);
  auto ok = s.client().Put("/v1/scenes", other, "model/gltf+json");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 201) << ok->body;
}

// Issue 30, queued jobs bounded by bytes: a decoded scene stays charged to the decode memory (64 MiB
// here) while the cache or a job holds it. Two renders holding 24 MiB scenes each (one running at the
// gate, one queued) leave no room for a third scene: its decode drops what only the cache holds, waits a
// second, and is refused with 503 decode-busy (it was queued before, every job holding its own scene).
// Once the queued job is cancelled its scene is only cached, and the third render gets its room.
TEST(ServerCore, QueuedRendersHoldTheirScenesInTheDecodeMemory) {
  ServerConfig config;
  config.maxDecodeBytes = 64u << 20;
  config.decodeMemoryBytes = 64u << 20;
  TestServer s(config);
  s.waitReady();
  auto c = s.client();
  std::vector<std::string> digests;
  for (int i = 0; i < 3; ++i) {
    const std::string doc = R"({"asset":{"version":"2.0"},"extras":{"scene-mib":24,"n":)" + std::to_string(i) + "}}";
    auto up = c.Put("/v1/scenes", doc, "model/gltf+json");
    ASSERT_TRUE(up);
    ASSERT_EQ(up->status, 201) << up->body;  // the third drops the first from the cache
    digests.push_back(body(up)["digest"]);
  }
  auto reserved = [&] {
    auto m = c.Get("/metrics");
    const std::string key = "\nradiant_decode_bytes_reserved ";
    const auto at = m->body.find(key);
    return at == std::string::npos ? -1.0 : std::stod(m->body.substr(at + key.size()));
  };
  EXPECT_EQ(reserved(), double(48u << 20));  // two scenes cached
  s.control.close();
  auto render = [&](int i) {
    json b = renderBody(10 + i);
    b["scene"] = {{"digest", digests[i]}};
    b["async"] = true;
    return post(c, "/v1/renders", b);
  };
  auto running = render(0);
  ASSERT_EQ(running->status, 202) << running->body;
  ASSERT_TRUE(s.control.waitStarted(1));
  auto queued = render(1);
  ASSERT_EQ(queued->status, 202) << queued->body;
  EXPECT_EQ(reserved(), double(48u << 20));  // the two held by the jobs; the third dropped from the cache
  const auto t0 = std::chrono::steady_clock::now();
  auto refused = render(2);
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.9);
  expectProblem(refused, 503, "decode-busy", "/scene/digest");
  EXPECT_EQ(refused->get_header_value("Retry-After"), "1");
  EXPECT_EQ(reserved(), double(48u << 20));
  auto del = c.Delete(("/v1/renders/" + body(queued)["id"].get<std::string>()).c_str());
  ASSERT_EQ(del->status, 200);
  auto admitted = render(2);
  ASSERT_EQ(admitted->status, 202) << admitted->body;
  EXPECT_EQ(reserved(), double(48u << 20));
  s.control.open();
  for (const auto& id : {body(running)["id"].get<std::string>(), body(admitted)["id"].get<std::string>()}) {
    const json st = waitForState(c, id, "done");
    EXPECT_EQ(st["state"], "done") << st.dump();
  }
  // Finished jobs (kept for their frames) hold no scene: only the cache's two remain charged.
  EXPECT_EQ(reserved(), double(48u << 20));
}

// Issue 30, the budgets together: decodes and request bodies are also held to --memory-limit-bytes
// (512 MiB here) against the process's resident set, which the test sets. Near the limit a decode that
// would cross it first drops the decoded scenes only the cache holds, then waits a second and is refused
// with 503 memory-busy and Retry-After (a body likewise, before it is read); one that fits beside still
// runs; a decode that is waiting gets its room when the resident set falls.
TEST(ServerCore, DecodesAndBodiesAreHeldToTheMemoryLimit) {
  ServerConfig config;
  config.memoryLimitBytes = 512u << 20;
  TestServer s(config);
  s.waitReady();
  auto c = s.client();
  auto metric = [&](const std::string& name) {
    auto m = c.Get("/metrics");
    const std::string key = "\n" + name + " ";
    const auto at = m->body.find(key);
    return at == std::string::npos ? -1.0 : std::stod(m->body.substr(at + key.size()));
  };
  // A decoded scene of 8 MiB that only the cache holds.
  auto cached = c.Put("/v1/scenes", R"({"asset":{"version":"2.0"},"extras":{"scene-mib":8,"n":1}})", "model/gltf+json");
  ASSERT_EQ(cached->status, 201) << cached->body;
  EXPECT_EQ(metric("radiant_decode_bytes_reserved"), double(8u << 20));

  s.control.resident = 500u << 20;
  const std::string big = R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":16,"n":2}})";
  const auto t0 = std::chrono::steady_clock::now();
  auto refused = c.Put("/v1/scenes", big, "model/gltf+json");
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.9);
  expectProblem(refused, 503, "memory-busy", "");
  EXPECT_EQ(refused->get_header_value("Retry-After"), "1");
  EXPECT_NE(json::parse(refused->body)["detail"].get<std::string>().find("--memory-limit-bytes"), std::string::npos);
  EXPECT_EQ(metric("radiant_memory_refused"), 1.0);
  EXPECT_EQ(metric("radiant_decode_bytes_reserved"), 0.0);  // the cached scene went first
  EXPECT_EQ(metric("radiant_decodes_refused"), 0.0);        // the decode budget had room
  // More than the limit itself: refused at once, whatever frees.
  const auto t1 = std::chrono::steady_clock::now();
  expectProblem(c.Put("/v1/scenes", R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":600,"n":5}})", "model/gltf+json"),
                503, "memory-busy", "");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 0.5);
  EXPECT_EQ(metric("radiant_memory_refused"), 2.0);

  // 500 + 8 MiB fits under 512.
  auto fits = c.Put("/v1/scenes", R"({"asset":{"version":"2.0"},"extras":{"reserve-mib":8,"n":3}})", "model/gltf+json");
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->status, 201) << fits->body;

  // A body of 600 KiB 100 KiB below the limit: refused on its Content-Length, its connection closed.
  s.control.resident = (512u << 20) - (100u << 10);
  const std::string padded = R"({"asset":{"version":"2.0"},"extras":{"n":4,"pad":")" + std::string(600 << 10, 'x') + "\"}}";
  auto body = s.client().Put("/v1/scenes", padded, "model/gltf+json");
  expectProblem(body, 503, "memory-busy", "");
  EXPECT_EQ(body->get_header_value("Connection"), "close");
  EXPECT_EQ(metric("radiant_memory_refused"), 3.0);

  // A waiting decode gets its room when the resident set falls within its second.
  s.control.resident = 500u << 20;
  std::thread later([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    s.control.resident = 100u << 20;
  });
  auto admitted = s.client().Put("/v1/scenes", big, "model/gltf+json");
  later.join();
  ASSERT_TRUE(admitted);
  EXPECT_EQ(admitted->status, 201) << admitted->body;
  EXPECT_EQ(metric("radiant_memory_refused"), 3.0);
}

TEST(ServerCore, MetricsCountRequestsPassesAndQueue) {
  TestServer s;
  s.waitReady();
  auto c = s.client();
  auto r = post(c, "/v1/renders", renderBody());
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(c.Get("/v1/nothing")->status, 404);
  auto m = c.Get("/metrics");
  ASSERT_EQ(m->status, 200);
  EXPECT_EQ(m->get_header_value("Content-Type").rfind("text/plain", 0), 0u);
  const std::string& t = m->body;
  EXPECT_NE(t.find("radiant_http_requests_total{status=\"200\"}"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_http_requests_total{status=\"404\"} 1"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_pass_duration_seconds_bucket{pass=\"fake_pass\",clock=\"gpu\",le=\"0.001\"} 1"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_pass_duration_seconds_count{pass=\"fake_pass\",clock=\"gpu\"} 1"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_render_duration_seconds_count 1"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_renders_total{result=\"done\"} 1"), std::string::npos) << t;
  EXPECT_NE(t.find("radiant_queue_depth 0"), std::string::npos) << t;
  EXPECT_NE(t.find("# TYPE radiant_render_seconds_total counter"), std::string::npos) << t;
}

TEST(ServerCore, BearerTokenGuardsEverythingButHealth) {
  ServerConfig config;
  config.token = "s3cret";
  TestServer s(config);
  auto c = s.client();
  EXPECT_EQ(c.Get("/v1/health")->status, 200);
  auto denied = c.Get("/v1/info");
  expectProblem(denied, 401, "unauthorized", "");
  EXPECT_EQ(denied->get_header_value("WWW-Authenticate"), "Bearer");
  EXPECT_EQ(c.Get("/v1/info", {{"Authorization", "Bearer wrong!"}})->status, 401);
  EXPECT_EQ(c.Get("/v1/info", {{"Authorization", "Bearer s3cret"}})->status, 200);
}

TEST(ServerCore, ShutdownFinishesInFlightAndRefusesNew) {
  TestServer s;
  s.waitReady();
  s.control.close();
  auto inflight = std::async(std::launch::async, [&s] {
    auto c = s.client();
    auto r = post(c, "/v1/renders", renderBody(9));
    return r ? r->status : -1;
  });
  ASSERT_TRUE(s.control.waitStarted(1));
  auto stopping = std::async(std::launch::async, [&s] { s.server->shutdown(); });
  auto c = s.client();
  for (int i = 0; i < 1000 && c.Get("/v1/ready")->status != 503; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  expectProblem(post(c, "/v1/renders", renderBody(10)), 503, "shutting-down", "");
  EXPECT_EQ(c.Get("/v1/ready")->status, 503);
  s.control.open();
  EXPECT_EQ(inflight.get(), 200);
  stopping.get();
  s.thread.join();
  s.server.reset();
}

TEST(ServerCore, BackendCreationFailureIsReportedAndRetried) {
  // The fake cannot create a context at first; /v1/ready says why, and recovers once it can.
  FakeControl control;
  control.failCreate = true;
  ServerConfig config;
  config.port = 0;
  HttpServer server(config, radiant::test::fakeHooks(control));
  const int port = server.bind();
  std::thread t([&] { server.run(); });
  httplib::Client c("127.0.0.1", port);
  while (control.creates < 1) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  auto r = c.Get("/v1/ready");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503);
  EXPECT_NE(json::parse(r->body)["detail"].get<std::string>().find("EGL_NOT_INITIALIZED"), std::string::npos) << r->body;
  control.failCreate = false;
  bool ready = false;
  for (int i = 0; i < 300 && !ready; ++i) {
    ready = c.Get("/v1/ready")->status == 200;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(ready);
  server.shutdown();
  t.join();
}

TEST(ServerConfig, FlagsOverrideTheConfigFileAndTheTokenComesFromAFile) {
  const auto dir = tempDir("config");
  std::ofstream(dir / "c.json") << R"({"max_queue": 3, "max_width": 100, "cache_dir": "/tmp/x", "request_timeout": 5})";
  std::ofstream(dir / "t") << "tok\n";
  auto c = radiant::server::parseCommandLine(
      {"--config", (dir / "c.json").string(), "--max-queue", "7", "--token-file", (dir / "t").string(), "--port=0"});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->maxQueue, 7);
  EXPECT_EQ(c->limits.maxWidth, 100);
  EXPECT_EQ(c->cacheDir, "/tmp/x");
  EXPECT_DOUBLE_EQ(c->requestTimeoutS, 5.0);
  EXPECT_EQ(c->token, "tok");
  EXPECT_EQ(c->port, 0);
  EXPECT_EQ(c->host, "127.0.0.1");
  EXPECT_THROW(radiant::server::parseCommandLine({"--token", "x"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-width", "5000"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-queue", "0"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--port", "http"}), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(ServerConfig, HardeningFlagsParseWithinTheirBounds) {
  auto c = radiant::server::parseCommandLine({"--max-json-depth", "32", "--max-decode-bytes", "1048576",
                                              "--scene-cache-bytes", "2097152", "--read-timeout", "2.5",
                                              "--keep-alive-timeout", "0.5", "--shutdown-grace", "0",
                                              "--max-connections", "64", "--gpu-scenes", "16"});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->limits.maxJsonDepth, 32u);
  EXPECT_EQ(c->maxDecodeBytes, 1048576u);
  EXPECT_EQ(c->sceneCacheBytes, 2097152u);
  EXPECT_DOUBLE_EQ(c->readTimeoutS, 2.5);
  EXPECT_DOUBLE_EQ(c->keepAliveTimeoutS, 0.5);
  EXPECT_DOUBLE_EQ(c->shutdownGraceS, 0.0);
  EXPECT_EQ(c->maxConnections, 64);
  EXPECT_EQ(c->gpuScenes, 16);
  EXPECT_EQ(radiant::server::parseCommandLine({})->gpuScenes, 4);
  EXPECT_THROW(radiant::server::parseCommandLine({"--gpu-scenes", "0"}), std::invalid_argument);
  // radiantd's grace default is 10 s; servers embedded in tests get 0.
  EXPECT_DOUBLE_EQ(radiant::server::parseCommandLine({})->shutdownGraceS, 10.0);
  EXPECT_DOUBLE_EQ(ServerConfig{}.shutdownGraceS, 0.0);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-json-depth", "7"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-json-depth", "1001"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-decode-bytes", "1000"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--read-timeout", "-1"}), std::invalid_argument);
  EXPECT_THROW(radiant::server::parseCommandLine({"--max-connections", "2"}), std::invalid_argument);
  // --speed-factor: auto (0, the default) or a pinned factor in [1/64, 64].
  EXPECT_EQ(radiant::server::parseCommandLine({})->speedFactor, 0.0);
  EXPECT_EQ(radiant::server::parseCommandLine({"--speed-factor", "auto"})->speedFactor, 0.0);
  EXPECT_EQ(radiant::server::parseCommandLine({"--speed-factor", "2.5"})->speedFactor, 2.5);
  EXPECT_EQ(radiant::server::parseCommandLine({"--speed-factor", "0.015625"})->speedFactor, 1.0 / 64);
  for (const char* bad : {"0", "-1", "nan", "inf", "65", "0.01", "fast", ""})
    EXPECT_THROW(radiant::server::parseCommandLine({"--speed-factor", bad}), std::invalid_argument) << bad;
}
