#include "renderer/frame/FrameAllocation.h"

#include <algorithm>
#include <string>

#include "api/Aovs.h"
#include "renderer/frame/FramePlanner.h"

namespace radiant {
namespace {
GLenum glFormat(api::AovFormat f) {
  switch (f) {
    case api::AovFormat::R32F: return GL_R32F;
    case api::AovFormat::Rgba16F: return GL_RGBA16F;
    default: return GL_RGBA32F;
  }
}
}  // namespace

void allocateDeclaredOutputs(FrameResources& res, const std::vector<Technique*>& passes) {
  const int w = res.view().width, h = res.view().height;
  for (const api::AovInfo& a : api::aovTable()) {
    if (a.resource.empty()) continue;
    bool declared = a.blend == api::AovBlend::Accumulate;  // beauty exists in every frame
    for (const Technique* t : passes) {
      const auto& outs = t->info().outputs;
      declared = declared || std::find(outs.begin(), outs.end(), a.name) != outs.end() ||
                 std::find(outs.begin(), outs.end(), a.resource) != outs.end();
    }
    if (!declared) continue;
    gl::Texture& t = res.texture(a.resource, GL_TEXTURE_2D, glFormat(a.format), w, h);
    if (a.blend != api::AovBlend::Accumulate) continue;
    // Zero, through a framebuffer: on llvmpipe a glClearTexImage here did not reach the next pass's
    // draws (the frame added onto the last one's beauty).
    gl::Framebuffer& fb = res.framebuffer("clear:" + a.resource);
    fb.attach(GL_COLOR_ATTACHMENT0, t);
    fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
    const float zero[4] = {0.f, 0.f, 0.f, 0.f};
    fb.checkComplete("allocateDeclaredOutputs");  // Mesa skips a clear of a framebuffer it has not validated
    glClearNamedFramebufferfv(fb.id(), GL_COLOR, 0, zero);
  }
}

void declareEnvironmentMap(FrameResources& res, const FrameView& view) {
  if (!view.environment) {
    // Keep a previous frame's map (the shaders do not sample it: u_hasEnvironment = 0).
    if (!res.hasTexture(kEnvironmentMap)) res.texture(kEnvironmentMap, GL_TEXTURE_2D, GL_RGBA32F, 1, 1);
    return;
  }
  const Image& env = *view.environment;
  // A full mip chain (box-filtered: each level keeps the mean radiance): the specular pass looks a
  // reflected ray up over its footprint's cone (common/environment.glsl environmentRadianceCone); a
  // level-0 texelFetch (every other lookup) is the nearest texel as before.
  int levels = 1;
  while ((std::max(env.width, env.height) >> levels) > 0) ++levels;
  gl::Texture& t = res.texture(kEnvironmentMap, GL_TEXTURE_2D, GL_RGBA32F, env.width, env.height, 1, levels);
  t.setFilter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
  t.setWrap(GL_REPEAT, GL_CLAMP_TO_EDGE);
  const std::string digest = view.environmentKey + "|" + std::to_string(env.width) + "x" + std::to_string(env.height);
  FrameResources::Refill map = res.refill(kEnvironmentMap, digest);
  if (map.hit()) return;
  std::vector<float> rgba(static_cast<std::size_t>(env.width) * env.height * 4, 0.f);
  for (std::size_t p = 0; p < static_cast<std::size_t>(env.width) * env.height; ++p)
    for (int c = 0; c < 3; ++c) rgba[p * 4 + c] = env.pixels[p * env.channels + std::min(c, env.channels - 1)];
  // Rows in image order (row 0 = up): texel row v * height is image row v * height.
  t.upload(0, 0, 0, 0, env.width, env.height, 1, GL_RGBA, GL_FLOAT, rgba.data());
  if (levels > 1) t.generateMipmaps();
  map.written();
}

}  // namespace radiant
