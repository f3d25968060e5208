#pragma once
// What the server needs from a renderer, as an interface, so the server core builds and is tested
// without GL (tests inject a deterministic fake; radiantd injects the real Renderer, see main.cpp).
//
// Threading contract:
//   createBackend() and every RenderBackend call run on the one render thread, which owns the GL
//   context for the backend's lifetime. Nothing else in the server touches it.
//   decodeScene, builtin*, encodeFrame are pure CPU and are called from HTTP / encoder threads.

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "api/Types.h"
#include "renderer/Image.h"
#include "renderer/Renderer.h"  // RenderOutput, TechniqueDescription, DeviceInfo (headers only: no GL)
#include "renderer/scene/Scene.h"

namespace radiant::server {

class RenderBackend {
public:
  virtual ~RenderBackend() = default;
  virtual DeviceInfo device() const = 0;
  // Throws api::ApiError for request problems found only while rendering (the job fails with that
  // status; the backend stays in use) and anything else for environment failures (the job fails
  // with 500 and the server destroys and recreates the backend before the next job).
  // `cancel` becomes true when the job is cancelled or times out; poll it between passes.
  // `inputs` holds the decoded images the request names by digest (compare.against, environment).
  virtual RenderOutput render(const Scene& scene, const api::RenderRequest& request,
                              const std::atomic<bool>* cancel, const FrameInputs& inputs) = 0;
  // What the backend's memory accountant may call (on the render thread) when it releases memory:
  // the server drops the decoded scenes and images no job holds. Default: not used.
  virtual void setReleaseHook(std::function<void()>) {}
};

struct BackendHooks {
  // Runs on the render thread; throws when no context can be created (the server retries with
  // backoff and /v1/ready says why).
  std::function<std::unique_ptr<RenderBackend>()> createBackend;
  // Memory admission for decoding (radiantd --decode-memory-bytes): a decoder calls it with each
  // allocation's size before making it; it may wait for memory other decodes hold and throws
  // api::ApiError 503 decode-busy when none frees in time, which the decoder passes on.
  using Reserve = std::function<void(std::size_t bytes)>;
  // glTF JSON or GLB bytes -> Scene. Throws api::ApiError (422) for files it cannot load.
  std::function<Scene(std::string_view bytes, const Reserve& reserve)> decodeScene;
  // EXR/HDR/PNG bytes -> Image, for compare.against an uploaded image. Throws api::ApiError (422).
  std::function<Image(std::string_view bytes, const Reserve& reserve)> decodeImage;
  std::function<std::vector<std::string>()> builtinSceneNames;
  std::function<std::string(const std::string& name)> builtinSceneSource;  // glTF/GLB bytes
  // One output file: EXR of every AOV in spec.aovs, or PNG of the single one with exposure applied.
  // `outputIndex` is the spec's index in request.outputs (for error pointers; see selectAovs()).
  std::function<std::string(const std::vector<Image>& aovs, const api::OutputSpec& spec, std::size_t outputIndex,
                            float exposureEV)>
      encodeFrame;
  std::vector<TechniqueDescription> techniques;  // what the backend implements (may be empty: unknown)
  // The request's problems with its scene that need no GL (Renderer::check: the planner's, the camera's,
  // the compare block's, each technique's validate()), thrown as api::ApiError before the job is
  // queued. Pure CPU, called on HTTP threads; unset: the render finds them (tests' fake backends).
  std::function<void(const Scene& scene, const api::RenderRequest& request, const FrameInputs& inputs)> checkFrame;
  // The process's resident set in bytes, which decodes and request bodies are admitted against under
  // --memory-limit-bytes (the renderer's own admission reads the same). Unset: radiant::residentBytes()
  // (renderer/ResidentMemory.h); tests inject one.
  std::function<std::size_t()> residentBytes;
};

}  // namespace radiant::server
