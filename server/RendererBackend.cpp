#include "server/RendererBackend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/scene/BuiltinScenes.h"
#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/GltfLoader.h"
#include "server/RenderService.h"

namespace radiant::server {

namespace {

// The largest pixel value an uploaded image may hold (docs/API.md, PUT /v1/images): 1e18 leaves 1e20 of
// float headroom (FLT_MAX 3.4e38) for the products and sums a radiance enters (solid angles, BRDF / pdf
// ratios, texel counts), while the brightest real maps hold an unclipped sun at 1e5 to 1e9.
constexpr float kMaxImageRadiance = 1e18f;

class RendererBackend final : public RenderBackend {
public:
  RendererBackend(const DeviceOptions& options, int gpuScenes, double speedFactor, std::size_t derivedBytes,
                  std::size_t memoryTarget, std::size_t memoryLimit)
      : renderer_(options) {
    renderer_.setGpuSceneCapacity(static_cast<std::size_t>(gpuScenes));
    renderer_.setDerivedCacheBytes(derivedBytes);
    renderer_.setMemoryTarget(memoryTarget);
    renderer_.setMemoryLimit(memoryLimit);
    renderer_.setSpeedFactor(speedFactor);
  }
  DeviceInfo device() const override { return renderer_.device(); }
  RenderOutput render(const Scene& scene, const api::RenderRequest& request, const std::atomic<bool>* cancel,
                      const FrameInputs& inputs) override {
    return renderer_.render(scene, request, cancel, inputs);
  }
  void setReleaseHook(std::function<void()> hook) override { renderer_.setReleaseHook(std::move(hook)); }

private:
  Renderer renderer_;
};

}  // namespace

BackendHooks rendererHooks(const ServerConfig& config) {
  DeviceOptions device;
  device.index = config.deviceIndex;
  device.nameContains = config.deviceName;
  device.cudaDevice = config.cudaDevice;
  device.debug = config.glDebug;

  BackendHooks h;
  const int gpuScenes = config.gpuScenes;
  const double speedFactor = config.speedFactor;
  const std::size_t derivedBytes = config.derivedCacheBytes;
  const std::size_t memoryTarget = config.memoryTargetBytes, memoryLimit = config.memoryLimitBytes;
  h.createBackend = [device, gpuScenes, speedFactor, derivedBytes, memoryTarget, memoryLimit] {
    return std::make_unique<RendererBackend>(device, gpuScenes, speedFactor, derivedBytes, memoryTarget, memoryLimit);
  };
  const std::size_t maxBytes = config.maxBodyBytes;
  const std::size_t maxDecoded = config.maxDecodeBytes;
  const std::size_t maxDepth = config.limits.maxJsonDepth;
  h.decodeScene = [maxBytes, maxDecoded, maxDepth](std::string_view bytes, const BackendHooks::Reserve& reserve) {
    LoadOptions options;  // empty asset root: uploads may not reference external files
    options.maxBytes = std::max<std::size_t>(maxBytes, std::size_t(256) << 20);
    options.maxDecodedBytes = maxDecoded;
    options.maxJsonDepth = maxDepth;
    options.reserveDecoded = reserve;
    // The pointer is into the glTF document; for an upload that is the request body.
    try {
      return loadSceneFromMemory(bytes, options);
    } catch (const SceneLimitError& e) {
      throw api::ApiError(422, "limit-exceeded", "Server limit exceeded",
                          std::string("the glTF file is over a limit") + (e.pointer.empty() ? "" : " at " + e.pointer) +
                              ": " + e.what(),
                          e.pointer);
    } catch (const SceneError& e) {
      throw api::ApiError(422, "invalid-scene", "Invalid scene",
                          std::string("the glTF file is invalid") +
                              (e.pointer.empty() ? "" : " at " + e.pointer) + ": " + e.what(),
                          e.pointer);
    }
  };
  h.decodeImage = [maxDecoded](std::string_view bytes, const BackendHooks::Reserve& reserve) {
    Image image;
    try {
      image = io::decodeImage(bytes, "beauty", maxDecoded, reserve);
    } catch (const api::ApiError&) {
      throw;  // the shared decode memory's 503
    } catch (const io::DecodeLimitExceeded& e) {
      throw api::ApiError(422, "limit-exceeded", "Server limit exceeded", e.what());
    } catch (const std::exception& e) {
      throw api::ApiError(422, "invalid-image", "Invalid image", e.what());
    }
    // Radiance is finite, non-negative and at most kMaxImageRadiance: a NaN would poison the
    // reference's importance-sampling distribution and every metric, and a value near FLT_MAX overflows
    // the float sums that weigh it (an environment's prefilter and distribution, a metric's squares), so
    // such an image is refused, naming the first bad pixel.
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < image.channels; ++c) {
          const float v = image.at(x, y)[c];
          if (!std::isfinite(v) || v < 0.f || v > kMaxImageRadiance) {
            char value[32];
            std::snprintf(value, sizeof value, "%g", double(v));
            throw api::ApiError(422, "invalid-image", "Invalid image",
                                "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " +
                                    std::to_string(c) + " is " + value +
                                    ": radiance must be finite, non-negative and at most 1e18");
          }
        }
    return image;
  };
  h.builtinSceneNames = [] { return builtinSceneNames(); };
  h.builtinSceneSource = [](const std::string& name) { return std::string(builtinSceneSource(name)); };
  h.encodeFrame = [](const std::vector<Image>& aovs, const api::OutputSpec& spec, std::size_t index, float exposure) {
    std::vector<Image> chosen = selectAovs(aovs, spec, index);
    // "background": "transparent": the Renderer adds the beauty's coverage ("alpha"), its A channel.
    const auto alpha = std::find_if(aovs.begin(), aovs.end(), [](const Image& i) { return i.aov == "alpha"; });
    const auto beauty = std::find_if(chosen.begin(), chosen.end(), [](const Image& i) { return i.aov == "beauty"; });
    const bool withAlpha = alpha != aovs.end() && beauty != chosen.end();
    if (spec.format == api::ImageFormat::Exr) {
      if (withAlpha) chosen.insert(beauty + 1, *alpha);
      return io::encodeExr(chosen, spec.halfFloat);
    }
    io::PngOptions png;
    png.exposureEV = exposure;
    png.toneMap = spec.toneMap;
    png.zlibLevel = spec.pngCompression;
    png.alpha = withAlpha ? &*alpha : nullptr;
    return io::encodePng(chosen.front(), png);
  };
  h.techniques = Renderer::techniques();
  h.checkFrame = [](const Scene& scene, const api::RenderRequest& request, const FrameInputs& inputs) {
    Renderer::check(scene, request, inputs);
  };
  return h;
}

}  // namespace radiant::server
