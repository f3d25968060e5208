#include "renderer/frame/FrameResources.h"

#include <cstdio>
#include <stdexcept>

#include "api/Aovs.h"
#include "renderer/frame/GpuScene.h"

namespace radiant {
namespace {
std::string hex(GLenum v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", static_cast<unsigned>(v));
  return buf;
}
}  // namespace

void FrameResources::beginFrame(const GpuScene& gpu, const FrameView& view, std::vector<api::CacheEvent>* cacheLog) {
  gpu_ = &gpu;
  view_ = &view;
  cacheLog_ = cacheLog;
  written_.clear();
  declaredThisFrame_.clear();
}

const std::string& FrameResources::sceneKey() const { return gpu_->sceneKey; }

gl::Texture& FrameResources::texture(const std::string& name, GLenum target, GLenum internalFormat, int width,
                                     int height, int depth, int levels) {
  const TextureSpec spec{target, internalFormat, width, height, depth, levels};
  for (const api::AovInfo& a : api::aovTable()) {
    if (a.resource != name) continue;
    const GLenum declared = a.format == api::AovFormat::R32F      ? GL_R32F
                            : a.format == api::AovFormat::Rgba16F ? GL_RGBA16F
                                                                  : GL_RGBA32F;
    if (internalFormat != declared)
      throw std::logic_error("FrameResources: '" + name + "' is the resource of AOV '" + a.name + "', declared " +
                             api::toString(a.format) + " in the AOV table (api/Aovs.cpp); a pass asked for format 0x" +
                             hex(internalFormat));
  }
  auto it = textures_.find(name);
  if (it != textures_.end() && it->second.first == spec) {
    declaredThisFrame_.insert(name);
    return it->second.second;
  }
  if (it != textures_.end() && declaredThisFrame_.count(name))
    throw std::logic_error("FrameResources: texture '" + name +
                           "' re-declared with another size or format in the same frame (it would lose what earlier "
                           "passes wrote into it)");
  declaredThisFrame_.insert(name);
  gl::Texture t(name, target, internalFormat, width, height, depth, levels);
  return textures_.insert_or_assign(name, std::make_pair(spec, std::move(t))).first->second.second;
}

gl::Texture& FrameResources::texture(const std::string& name) {
  auto it = textures_.find(name);
  if (it == textures_.end()) throw std::logic_error("FrameResources: texture '" + name + "' was never declared");
  return it->second.second;
}

gl::Framebuffer& FrameResources::framebuffer(const std::string& name) {
  auto it = framebuffers_.find(name);
  if (it == framebuffers_.end()) it = framebuffers_.emplace(name, gl::Framebuffer(name)).first;
  return it->second;
}

gl::Buffer& FrameResources::buffer(const std::string& name, std::size_t bytes, GLbitfield flags) {
  auto it = buffers_.find(name);
  if (it != buffers_.end() && it->second.size() == bytes) return it->second;
  return buffers_.insert_or_assign(name, gl::Buffer(name, bytes, nullptr, flags)).first->second;
}

gl::Buffer& FrameResources::buffer(const std::string& name) {
  auto it = buffers_.find(name);
  if (it == buffers_.end()) throw std::logic_error("FrameResources: buffer '" + name + "' was never declared");
  return it->second;
}

void FrameResources::clear() {
  textures_.clear();
  framebuffers_.clear();
  buffers_.clear();
  cache_.clear();
  written_.clear();
  declaredThisFrame_.clear();
}

}  // namespace radiant
