#include "renderer/frame/FrameResources.h"

#include <algorithm>
#include <stdexcept>

#include <malloc.h>

#include "api/Aovs.h"
#include "renderer/frame/FrameView.h"
#include "renderer/frame/GpuScene.h"
#include "renderer/ResidentMemory.h"

namespace radiant {
namespace {
std::string hex(GLenum v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", static_cast<unsigned>(v));
  return buf;
}
}  // namespace

const char* toString(Access access) {
  switch (access) {
    case Access::Read: return "Read";
    case Access::Write: return "Write";
    case Access::WriteInPrepare: return "WriteInPrepare";
    default: return "Accumulate";
  }
}

void FrameResources::beginPass(std::string pass, std::vector<ResourceAccess> access, Phase phase) {
  pass_ = std::move(pass);
  access_ = std::move(access);
  phase_ = phase;
  inPass_ = true;
  if (phase == Phase::Execute) passWrites_.clear();
}

const ResourceAccess* FrameResources::declaration(const std::string& name) const {
  const auto it = std::find_if(access_.begin(), access_.end(), [&](const ResourceAccess& a) { return a.name == name; });
  return it == access_.end() ? nullptr : &*it;
}

void FrameResources::checkAccess(const std::string& name, bool write) const {
  if (!inPass_) return;
  if (!write && !shared_.count(name)) return;
  const ResourceAccess* it = declaration(name);
  std::string declared;
  for (const ResourceAccess& a : access_) declared += (declared.empty() ? "" : ", ") + a.name + ":" + toString(a.access);
  if (!it)
    throw std::logic_error("FrameResources: pass " + pass_ + (write ? " wrote '" : " used '") + name +
                           "', which its TechniqueInfo does not declare (it declares " +
                           (declared.empty() ? std::string("nothing") : declared) + ")");
  if (write && it->access == Access::Read)
    throw std::logic_error("FrameResources: pass " + pass_ + " wrote '" + name + "', which it declares Read only");
  if (write && it->access == Access::WriteInPrepare && phase_ == Phase::Execute)
    throw std::logic_error("FrameResources: pass " + pass_ + " wrote '" + name +
                           "' in execute(), which it declares written in prepare() (prepare_outputs): its readers "
                           "may already have run");
}

void FrameResources::checkNoAllocation(const std::string& what, const std::string& name) const {
  if (inPass_ && phase_ == Phase::Execute)
    throw std::logic_error("FrameResources: pass " + pass_ + " allocated " + what + " '" + name +
                           "' in execute(); declare it in prepare()");
}

void FrameResources::markWritten(const std::string& name) {
  checkAccess(name, true);
  if (const ResourceAccess* d = inPass_ ? declaration(name) : nullptr; d && d->access == Access::Accumulate)
    throw std::logic_error("FrameResources: pass " + pass_ + " marked '" + name +
                           "' written; a pass composes into it through a BeautyWrite (renderer/frame/Beauty.h)");
  written_.insert(name);
  passWrites_.insert(name);
}

BeautyBlend FrameResources::declaredBlend(const std::string& name) const {
  if (!inPass_)
    throw std::logic_error("FrameResources: a composition into '" + name + "' outside a pass scope");
  const ResourceAccess* d = declaration(name);
  if (!d || d->access != Access::Accumulate)
    throw std::logic_error("FrameResources: pass " + pass_ + " composed into '" + name +
                           "', which its TechniqueInfo does not declare (adds_to_beauty)");
  return d->blend;
}

void FrameResources::accumulate(const std::string& name) {
  const BeautyBlend blend = declaredBlend(name);
  std::vector<Composition>& versions = compositions_[name];
  if (!versions.empty() && versions.back().blend > blend)
    throw std::logic_error("FrameResources: pass " + pass_ + " composed into '" + name + "' with " +
                           toString(blend) + " after pass " + versions.back().pass + "'s " +
                           toString(versions.back().blend) + " (the frame graph orders add, over, transmit)");
  versions.push_back({pass_, blend});
  written_.insert(name);
  passWrites_.insert(name);
}

const std::vector<FrameResources::Composition>& FrameResources::compositions(const std::string& name) const {
  static const std::vector<Composition> none;
  const auto it = compositions_.find(name);
  return it == compositions_.end() ? none : it->second;
}

void FrameResources::beginFrame(const GpuScene& gpu, const FrameView& view, std::vector<api::CacheEvent>* cacheLog) {
  gpu_ = &gpu;
  view_ = &view;
  // The frame's camera, once for every pass (common/frame.glsl).
  const gpu::FrameConstants constants = frameConstants(view);
  if (frameConstants_.id() == 0) frameConstants_ = gl::Buffer("frame_constants", sizeof(constants));
  frameConstants_.upload(&constants, sizeof(constants));
  frameConstants_.bindBase(GL_UNIFORM_BUFFER, gpu::kBindingFrameConstants);
  cacheLog_ = cacheLog;
  ++frame_;
  cancel_ = {};
  endPass();  // a pass that threw last frame left its scope open
  written_.clear();
  compositions_.clear();
  products_.clear();
  declaredThisFrame_.clear();
  usedThisFrame_.clear();
  releasedThisFrame_ = 0;
}

const std::string& FrameResources::sceneKey() const { return gpu_->sceneKey; }

std::size_t FrameResources::derivedBytes() const {
  std::size_t total = 0;
  for (const auto& [key, entries] : cache_)
    for (const auto& e : entries)
      if (e.value.bytes) total += e.value.bytes();
  return total;
}

void FrameResources::keepWithinDerivedBytes() {
  std::size_t total = derivedBytes();
  while (total > derivedBytes_) {
    // The least recently used sized entry of an earlier frame: the oldest frame, then the back of its list.
    Family* from = nullptr;
    Family::iterator victim;
    for (auto& [key, entries] : cache_)
      for (auto it = entries.begin(); it != entries.end(); ++it)
        if (it->value.bytes && it->value.frame != frame_ && (!from || it->value.frame <= victim->value.frame)) {
          from = &entries;
          victim = it;
        }
    if (!from) return;  // only this frame's entries are left
    total -= victim->value.bytes();
    from->erase(victim);
  }
}

gl::Texture& FrameResources::texture(const std::string& name, GLenum target, GLenum internalFormat, int width,
                                     int height, int depth, int levels) {
  const TextureSpec spec{target, internalFormat, width, height, depth, levels};
  checkAccess(name, false);
  used(name);
  for (const api::AovInfo& a : api::aovTable()) {
    if (a.resource != name) continue;
    const GLenum declared = a.format == api::AovFormat::R32F      ? GL_R32F
                            : a.format == api::AovFormat::Rgba16F ? GL_RGBA16F
                                                                  : GL_RGBA32F;
    if (internalFormat != declared)
      throw std::logic_error("FrameResources: '" + name + "' is the resource of AOV '" + a.name + "', declared " +
                             api::toString(a.format) + " in the AOV table (its producer's descriptor, \"aovs\"); " +
                             "a pass asked for format 0x" + hex(internalFormat));
  }
  auto it = textures_.find(name);
  if (it != textures_.end() && it->second.first == spec) {
    declaredThisFrame_.insert(name);
    return it->second.second;
  }
  if (it != textures_.end() && declaredThisFrame_.count(name))
    throw std::logic_error("FrameResources: texture '" + name +
                           "' re-declared with another size or format in the same frame (it would lose what earlier "
                           "passes wrote into it)" + (inPass_ ? " by pass " + pass_ : std::string()));
  checkNoAllocation("texture", name);
  declaredThisFrame_.insert(name);
  holds_.erase(name);  // a new texture holds nothing
  gl::Texture t(name, target, internalFormat, width, height, depth, levels);
  return textures_.insert_or_assign(name, std::make_pair(spec, std::move(t))).first->second.second;
}

gl::Texture& FrameResources::texture(const std::string& name) {
  checkAccess(name, false);
  used(name);
  auto it = textures_.find(name);
  if (it == textures_.end()) throw std::logic_error("FrameResources: texture '" + name + "' was never declared");
  return it->second.second;
}

gl::Framebuffer& FrameResources::framebuffer(const std::string& name) {
  used(name);
  auto it = framebuffers_.find(name);
  if (it == framebuffers_.end()) {
    checkNoAllocation("framebuffer", name);
    it = framebuffers_.emplace(name, gl::Framebuffer(name)).first;
  }
  return it->second;
}

gl::Buffer& FrameResources::buffer(const std::string& name, std::size_t bytes, GLbitfield flags) {
  used(name);
  auto it = buffers_.find(name);
  if (it != buffers_.end() && it->second.size() == bytes) return it->second;
  checkNoAllocation("buffer", name);
  holds_.erase(name);  // a new buffer holds nothing
  return buffers_.insert_or_assign(name, gl::Buffer(name, bytes, nullptr, flags)).first->second;
}

gl::Buffer& FrameResources::buffer(const std::string& name) {
  used(name);
  auto it = buffers_.find(name);
  if (it == buffers_.end()) throw std::logic_error("FrameResources: buffer '" + name + "' was never declared");
  return it->second;
}

FrameResources::Refill FrameResources::refill(const std::string& resource, std::string digest, const std::string& logKey) {
  Refill r;
  r.resources_ = this;
  r.resource_ = resource;
  auto it = holds_.find(resource);
  r.hit_ = !digest.empty() && it != holds_.end() && it->second == digest;
  if (!r.hit_ && it != holds_.end()) holds_.erase(it);  // about to be overwritten: holds nothing until written()
  r.digest_ = std::move(digest);
  if (cacheLog_ && !r.digest_.empty()) cacheLog_->push_back({logKey.empty() ? resource : logKey, r.hit_});
  return r;
}

void FrameResources::Refill::written() {
  if (resources_ && !digest_.empty()) resources_->holds_[resource_] = digest_;
}

void FrameResources::clear() {
  textures_.clear();
  framebuffers_.clear();
  buffers_.clear();
  cache_.clear();
  holds_.clear();
  written_.clear();
  compositions_.clear();
  declaredThisFrame_.clear();
  usedThisFrame_.clear();
}

std::size_t FrameResources::resourceBytes() const {
  std::size_t total = 0;
  for (const auto& [name, entry] : textures_) total += gl::textureBytes(entry.second);
  for (const auto& [name, buffer] : buffers_) total += buffer.size();
  return total;
}

std::size_t FrameResources::residentBytes() { return radiant::residentBytes(); }

void FrameResources::releaseIdle() {
  auto idle = [&](const std::string& name) { return usedThisFrame_.count(name) == 0; };
  for (auto it = framebuffers_.begin(); it != framebuffers_.end();)
    it = idle(it->first) ? framebuffers_.erase(it) : std::next(it);
  for (auto it = textures_.begin(); it != textures_.end();) {
    if (!idle(it->first)) { ++it; continue; }
    holds_.erase(it->first);
    it = textures_.erase(it);
  }
  for (auto it = buffers_.begin(); it != buffers_.end();) {
    if (!idle(it->first)) { ++it; continue; }
    holds_.erase(it->first);
    it = buffers_.erase(it);
  }
  for (auto& [key, entries] : cache_) entries.evict([](const Family&) { return true; },
                                                    [&](const Family::Entry& e) { return e.value.frame == frame_; },
                                                    [](Family::Entry&&) {});
  if (trimHook_) trimHook_();
  malloc_trim(0);
}

std::size_t FrameResources::textureAllocation(const std::string& name, GLenum target, GLenum internalFormat,
                                              int width, int height, int depth, int levels) const {
  auto it = textures_.find(name);
  if (it != textures_.end() && it->second.first == TextureSpec{target, internalFormat, width, height, depth, levels})
    return 0;
  return gl::textureBytes(target, internalFormat, width, height, depth, levels);
}

std::size_t FrameResources::makeRoom(std::size_t bytes) {
  const std::size_t before = residentBytes();
  if (before == 0 || before + bytes <= std::min(memoryTarget_, memoryLimit_ ? memoryLimit_ : memoryTarget_)) return 0;
  releaseIdle();
  const std::size_t after = residentBytes();
  const std::size_t released = before > after ? before - after : 0;
  releasedThisFrame_ += released;
  return released;
}

std::size_t FrameResources::settleAfterFrame() {
  std::size_t released = makeRoom(0);
  const std::size_t before = residentBytes();
  if (!memoryLimit_ || before <= memoryLimit_) return released;
  usedThisFrame_.clear();  // the frame is over: its targets are idle now
  releaseIdle();
  const std::size_t after = residentBytes();
  if (before > after) {
    released += before - after;
    releasedThisFrame_ += before - after;
  }
  return released;
}

void FrameResources::admit(std::size_t bytes, const std::string& pointer) {
  if (!memoryLimit_) return;
  // The frame's earlier allocations are resident now: its claim is the next one alone.
  std::size_t after = 0;
  if (MemoryClaims::process().tryReplace(claim_, bytes, memoryLimit_, residentBytes, &after)) {
    claim_ = bytes;
    return;
  }
  const auto mib = [](std::size_t b) { return std::to_string(b >> 20); };
  const std::size_t others = MemoryClaims::process().claimed() - claim_;
  throw api::ApiError(503, "memory-busy", "Not enough memory",
                      (pointer.empty() ? std::string("this frame") : pointer) + " needs about " + mib(bytes) +
                          " MiB more; the daemon holds " + mib(after) + " MiB after releasing what the frame does "
                          "not use (decoded scenes of queued renders among it) and decodes and request bodies in "
                          "flight claim " + mib(others) + " MiB more, above its limit of " + mib(memoryLimit_) +
                          " MiB (--memory-limit-bytes): retry after the Retry-After seconds, or ask for less",
                      pointer);
}

void FrameResources::releaseClaim() {
  if (claim_) MemoryClaims::process().release(claim_);
  claim_ = 0;
}

}  // namespace radiant
