#pragma once
// A deterministic render backend for testing the server without GL. Every pixel of "beauty" is
// seed + 0.25, so a frame proves which request it belongs to; the encoder writes a one-line text
// "frame" that the tests parse. A shared FakeControl lets a test hold renders (gate), make one
// fail, or count backend creations.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "api/Validate.h"
#include "renderer/ResidentMemory.h"
#include "server/Backend.h"
#include "server/RenderService.h"

namespace radiant::test {

struct FakeControl {
  std::mutex m;
  std::condition_variable cv;
  bool gateOpen = true;
  std::atomic<int> creates{0}, started{0}, finished{0};
  std::atomic<bool> failNext{false}, apiErrorNext{false}, failCreate{false};
  std::atomic<int> delayMs{0};
  // Scene decodes of a document holding "hold-decode" wait while holdDecode is set (decoding counts them).
  std::atomic<bool> holdDecode{false};
  std::atomic<int> decoding{0};
  // Image decodes (uploads and the images renders name); one of bytes holding "hold-image" waits while
  // holdDecode is set (imageDecoding counts those waiting).
  std::atomic<int> imageDecodes{0}, imageDecoding{0};
  // The resident set the server sees (--memory-limit-bytes admission); 0: the test process's own.
  std::atomic<std::size_t> resident{0};

  void close() { std::lock_guard l(m); gateOpen = false; }
  void open() { { std::lock_guard l(m); gateOpen = true; } cv.notify_all(); }
  // Waits until `n` renders have started (the render thread holds one).
  bool waitStarted(int n, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (started < n) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
};

class FakeBackend final : public server::RenderBackend {
public:
  explicit FakeBackend(FakeControl& c) : c_(c) {}
  DeviceInfo device() const override {
    DeviceInfo d;
    d.vendor = "Radiant tests";
    d.renderer = "fake";
    d.version = "4.5 (fake)";
    d.platform = "none";
    d.reason = "injected by the test";
    d.software = true;
    return d;
  }
  RenderOutput render(const Scene& scene, const api::RenderRequest& r, const std::atomic<bool>* cancel,
                      const FrameInputs& inputs) override {
    ++c_.started;
    if (inputs.progress) inputs.progress(0.5);  // half the frame, then wait at the gate
    {
      std::unique_lock l(c_.m);
      while (!c_.gateOpen && !(cancel && *cancel)) c_.cv.wait_for(l, std::chrono::milliseconds(5));
    }
    for (int waited = 0; waited < c_.delayMs && !(cancel && *cancel); waited += 5)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (c_.failNext.exchange(false)) throw std::runtime_error("glDrawElements: GL_OUT_OF_MEMORY (fake)");
    if (c_.apiErrorNext.exchange(false))
      throw api::ApiError(422, "unknown-receiver", "Unknown receiver", "no node named 'floor' (fake)", "/passes/direct");
    RenderOutput out;
    Image beauty = Image::make("beauty", r.width, r.height, 3);
    for (float& v : beauty.pixels) v = static_cast<float>(r.seed) + 0.25f;
    out.aovs.push_back(beauty);
    Image depth = Image::make("depth", r.width, r.height, 1);
    out.aovs.push_back(depth);
    api::PassStats p;
    p.name = "fake_pass";
    p.gpuMs = 1.0;
    p.cpuMs = 0.5;
    p.counters["pixels"] = double(r.width) * r.height;
    out.stats.passes.push_back(p);
    out.stats.triangles = scene.features.triangles;
    out.stats.device["renderer"] = "fake";
    ++c_.finished;
    return out;
  }

private:
  FakeControl& c_;
};

inline const char* kTinyGltf = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})";

inline server::BackendHooks fakeHooks(FakeControl& c) {
  server::BackendHooks h;
  h.createBackend = [&c]() -> std::unique_ptr<server::RenderBackend> {
    ++c.creates;
    if (c.failCreate) throw std::runtime_error("eglInitialize failed: EGL_NOT_INITIALIZED (fake)");
    return std::make_unique<FakeBackend>(c);
  };
  h.decodeScene = [&c](std::string_view bytes, const server::BackendHooks::Reserve& reserve) {
    // {"extras": {"reserve-mib": N}}: the decode takes N MiB of the shared decode memory first.
    if (const auto at = bytes.find("\"reserve-mib\":"); at != std::string_view::npos && reserve)
      reserve(std::size_t(std::atoi(std::string(bytes.substr(at + 14, 8)).c_str())) << 20);
    if (bytes.find("hold-decode") != std::string_view::npos) {
      ++c.decoding;
      while (c.holdDecode) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      --c.decoding;
    }
    Scene s;
    // {"extras": {"scene-mib": N}}: the decoded scene holds an N MiB texture, reserved first as the
    // real decoder does.
    if (const auto at = bytes.find("\"scene-mib\":"); at != std::string_view::npos) {
      const std::size_t n = std::size_t(std::atoi(std::string(bytes.substr(at + 12, 8)).c_str())) << 20;
      if (reserve) reserve(n);
      Texture t;
      t.width = int(n / 4);
      t.height = 1;
      t.rgba8.assign(n, 0);
      s.textures.push_back(std::move(t));
    }
    const bool glb = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
    if (!glb) {
      nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
      if (j.is_discarded() || !j.is_object() || !j.contains("asset"))
        throw api::ApiError(422, "invalid-scene", "Invalid scene", "the glTF file is invalid at /asset: missing (fake)");
    }
    s.name = glb ? "glb" : "gltf";
    s.features.triangles = bytes.size();  // lets a test see which bytes reached the renderer
    return s;
  };
  h.decodeImage = [&c](std::string_view bytes, const server::BackendHooks::Reserve&) {
    ++c.imageDecodes;
    if (bytes.find("hold-image") != std::string_view::npos) {
      ++c.imageDecoding;
      while (c.holdDecode) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      --c.imageDecoding;
    }
    Image im = Image::make("beauty", 2, 1, 3);
    for (float& v : im.pixels) v = 0.5f;
    return im;
  };
  h.builtinSceneNames = [] { return std::vector<std::string>{"tiny", "tiny2"}; };
  h.builtinSceneSource = [](const std::string& name) {
    if (name == "tiny") return std::string(kTinyGltf);
    if (name == "tiny2") return std::string(R"({"asset":{"version":"2.0"},"extras":{"n":2}})");
    throw std::out_of_range("no builtin " + name);
  };
  h.encodeFrame = [](const std::vector<Image>& aovs, const api::OutputSpec& spec, std::size_t index, float exposure) {
    std::vector<Image> chosen = server::selectAovs(aovs, spec, index);
    nlohmann::json j{{"format", api::toString(spec.format)}, {"width", chosen[0].width}, {"height", chosen[0].height},
                     {"value", chosen[0].pixels.empty() ? 0.f : chosen[0].pixels[0]}, {"exposure", exposure}};
    for (const auto& img : chosen) j["aovs"].push_back(img.aov);
    return "FAKEFRAME " + j.dump();
  };
  h.residentBytes = [&c] {
    const std::size_t r = c.resident.load();
    return r ? r : radiant::residentBytes();
  };
  h.techniques = {{"direct", "fake direct", {"direct"}},
                  {"gbuffer", "fake gbuffer", {"albedo", "normal", "depth"}},
                  {"shadow_maps", "fake shadow maps", {}}};
  return h;
}

}  // namespace radiant::test
