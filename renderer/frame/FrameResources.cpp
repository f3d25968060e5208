#include "renderer/frame/FrameResources.h"

#include <stdexcept>

#include "renderer/frame/GpuScene.h"

namespace radiant {

void FrameResources::beginFrame(const GpuScene& gpu, const FrameView& view, std::vector<api::CacheEvent>* cacheLog) {
  gpu_ = &gpu;
  view_ = &view;
  cacheLog_ = cacheLog;
  written_.clear();
}

const std::string& FrameResources::sceneKey() const { return gpu_->sceneKey; }

gl::Texture& FrameResources::texture(const std::string& name, GLenum target, GLenum internalFormat, int width,
                                     int height, int depth, int levels) {
  const TextureSpec spec{target, internalFormat, width, height, depth, levels};
  auto it = textures_.find(name);
  if (it != textures_.end() && it->second.first == spec) return it->second.second;
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
}

}  // namespace radiant
