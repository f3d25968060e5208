#pragma once
// Named GPU resources and cached derived data, owned across frames.
//
// Textures, framebuffers and buffers are declared by name in a technique's prepare(): a declaration
// with the same spec as last frame returns the same object, so steady-state frames allocate nothing.
// The Renderer declares the planned passes' AOV outputs, beauty and the environment map before any
// pass (renderer/frame/FrameAllocation.h); passes look those up by name, as their TechniqueInfo
// declares (beginPass below).
// Derived data a cache entry owns (BVHs, photons, beams, objects with their own GL storage) is cached
// under a key together with the digest of exactly the inputs it depends on; every lookup is logged as
// a cache hit or miss. Each key keeps the derived data of its `derivedCapacity` most recently used
// digests (renders alternating between scenes or parameter sets reuse them; radiantd --gpu-scenes sets
// it with the scene cache). Derived data that lives in a shared frame resource (shadow maps, cube maps,
// uploaded buffers) is valid only while the resource holds it: refill() below.
// Derived data whose type reports its size (`std::size_t bytes() const`: photon sets, splat grids) is
// also kept within a byte budget over every key together (radiantd --derived-cache-bytes): when an entry
// is added, the least recently used entries go first, never one this frame has looked up (a pass may
// hold a reference to it).
#include <any>
#include <concepts>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#include "api/LightPaths.h"
#include "api/Lru.h"
#include "api/Types.h"
#include "renderer/frame/BeautyBlend.h"
#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/raytracing/Cancel.h"

namespace radiant {

class GpuScene;
struct FrameView;

// How a pass uses a shared resource (Falcor's RenderPassReflection, Filament's FrameGraph): Read (one of
// its inputs or optional inputs), Write (an output it overwrites), WriteInPrepare (an output its
// prepare() publishes, TechniqueInfo::prepareOutputs: written in execute() it is a breach), Accumulate
// (composes into an accumulate AOV: beauty, with `blend`). FramePlanner's declaredAccess() derives a
// pass's list from its TechniqueInfo.
enum class Access { Read, Write, WriteInPrepare, Accumulate };
struct ResourceAccess {
  std::string name;
  Access access;
  BeautyBlend blend = BeautyBlend::Add;  // Accumulate: TechniqueInfo::beautyBlend
};
const char* toString(Access access);

class FrameResources {
public:
  explicit FrameResources(gl::ShaderLibrary& shaders) : shaders_(shaders) {}

  // Called by the Renderer at the start of each frame.
  void beginFrame(const GpuScene& gpu, const FrameView& view, std::vector<api::CacheEvent>* cacheLog);
  const GpuScene& gpuScene() const { return *gpu_; }
  // The frame's cancel token (renderer/raytracing/Cancel.h), for prepare() and the derived-data builders
  // (photon tracing, the BVH, beams), which see no PassContext. Set by the Renderer after beginFrame().
  void setCancel(rt::Cancel cancel) { cancel_ = cancel; }
  const rt::Cancel& cancel() const { return cancel_; }
  // The frame's scene identity for cache keys of derived data (GpuScene::sceneKey).
  const std::string& sceneKey() const;
  const FrameView& view() const { return *view_; }
  gl::ShaderLibrary& shaders() { return shaders_; }

  // Declare-or-reuse a texture. Re-declaring with a different spec in a later frame reallocates; within
  // one frame it throws std::logic_error (it would drop what earlier passes wrote, e.g. accumulated
  // beauty), and so does declaring an AOV's resource in another format than the AOV table's.
  gl::Texture& texture(const std::string& name, GLenum target, GLenum internalFormat, int width,
                       int height, int depth = 1, int levels = 1);
  // An already declared texture; throws std::logic_error naming it otherwise.
  gl::Texture& texture(const std::string& name);
  bool hasTexture(const std::string& name) const {
    used(name);
    return textures_.count(name) != 0;
  }
  gl::Framebuffer& framebuffer(const std::string& name);
  gl::Buffer& buffer(const std::string& name, std::size_t bytes, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
  gl::Buffer& buffer(const std::string& name);
  bool hasBuffer(const std::string& name) const {
    used(name);
    return buffers_.count(name) != 0;
  }

  // Derived data that lives in a frame resource shared by every scene (the shadow maps, the specular
  // and env_diffuse cube maps, the environment map and its prefiltered levels, uploaded beams): the
  // resource holds only what was last written into it, however many digests cached() keeps. A cache
  // hit for scene A after scene B wrote the resource would read B's data, so such data is written
  // through a Refill:
  //   FrameResources::Refill maps = res.refill("shadow_cube", digest, "shadow_maps");
  //   if (!maps.hit()) { ...write the maps...; maps.written(); }
  // refill() asks whether `resource` still holds what `digest` describes (logged as a hit or miss of
  // `logKey`, default the resource's name). On a miss the resource holds nothing from that moment:
  // whatever stops the pass before written() (a cancel, a 422 or 409, an exception) leaves it to be
  // redrawn, never claiming what it held before the write began. An empty digest is data that is not
  // cached (drawn every frame): never a hit, and it empties the resource too. Reallocating a texture or
  // buffer, and clear(), forget what it held.
  class Refill {
   public:
    Refill() = default;
    bool hit() const { return hit_; }
    // After writing: the resource holds this refill's digest (a no-op for an empty digest).
    void written();
    const std::string& digest() const { return digest_; }

   private:
    friend class FrameResources;
    FrameResources* resources_ = nullptr;
    std::string resource_, digest_;
    bool hit_ = false;
  };
  Refill refill(const std::string& resource, std::string digest, const std::string& logKey = "");
  // What `resource` holds (the digest of its last Refill::written), "" when nothing: data derived from it (the
  // caustic cubes from the specular maps) keys its own cache on it.
  std::string heldDigest(const std::string& resource) const {
    auto it = holds_.find(resource);
    return it == holds_.end() ? std::string() : it->second;
  }

  // Which technique owns each light-path class this frame (FramePlan::lightPaths, FramePlan::owned).
  void setLightPathOwners(std::map<std::string, std::string> owners, std::map<std::string, api::LightPathMask> owned) {
    lightPaths_ = std::move(owners);
    owned_ = std::move(owned);
  }
  // Whether `technique` owns every class of `classes` (api::kPath* bits) this frame.
  bool owns(const std::string& technique, api::LightPathMask classes) const {
    auto it = owned_.find(technique);
    return classes != 0 && it != owned_.end() && (it->second & classes) == classes;
  }
  // The technique that owns the class `cls` (one bit) this frame ("" when none claims it).
  std::string ownerOf(api::LightPathMask cls) const {
    auto it = lightPaths_.find(std::string(api::lightPathName(cls)));
    return it == lightPaths_.end() ? std::string() : it->second;
  }

  // Outputs written this frame (the planner and readback consult it). Inside a pass scope, marking a
  // resource the pass did not declare Write throws std::logic_error, and so does marking an accumulate
  // AOV (beauty), which a pass composes into only through accumulate() (renderer/frame/Beauty.h).
  void markWritten(const std::string& name);
  bool written(const std::string& name) const { return written_.count(name) != 0; }

  // Beauty as a versioned read-modify-write resource (Filament's FrameGraph: every write makes a new
  // version of the resource). A composition into an accumulate AOV is one version: `pass`'s write with
  // the blend its TechniqueInfo declares.
  struct Composition {
    std::string pass;
    BeautyBlend blend;
  };
  // The blend the current pass declares for the accumulate AOV `name`; throws std::logic_error when
  // it declares no Accumulate of `name` (or outside a pass scope).
  BeautyBlend declaredBlend(const std::string& name) const;
  // Records the current pass's composition into `name` as its next version and marks it written.
  // Versions compose in the order of their blends (Add, then Over, then Transmit: FramePlanner's
  // executionOrder); a composition of an earlier blend after a later one is a std::logic_error naming
  // both passes (an add after an over would add light behind a blended surface in front of it).
  void accumulate(const std::string& name);
  // The compositions into `name` this frame, in order (its version is their count).
  const std::vector<Composition>& compositions(const std::string& name) const;

  // The frame's typed blackboard (Filament's FrameGraph blackboard): what a pass hands to later passes
  // that is not one texture (photon_gi's splat grid, specular's layered distance maps) is a value
  // published under one of the pass's declared outputs and read under one of the reader's declared
  // inputs, so no pass looks up another's private resource names. publish() marks the name written
  // (checked like markWritten); product() is nullptr until it is published this frame, and reading it
  // as another type is a programmer error (std::logic_error). Products live for one frame.
  template <class T>
  void publish(const std::string& name, T value) {
    markWritten(name);
    products_[name] = std::move(value);
  }
  template <class T>
  const T* product(const std::string& name) const {
    checkAccess(name, false);
    // Products are read in execute(): in prepare() the frame graph's order promises nothing (every
    // prepare runs before any execute, in an order that follows only what executes read).
    if (inPass_ && phase_ == Phase::Prepare)
      throw std::logic_error("FrameResources: pass " + pass_ + " read the product '" + name +
                             "' in prepare(); products are read in execute()");
    used(name);
    const auto it = products_.find(name);
    if (it == products_.end()) return nullptr;
    const T* p = std::any_cast<T>(&it->second);
    if (!p)
      throw std::logic_error("FrameResources: '" + name + "' holds a " + it->second.type().name() + ", not a " +
                             typeid(T).name());
    return p;
  }

  // Declared resource access. The shared resources are the names passes exchange: every technique's
  // outputs, the AOV table's resources and the frame resources (environment_map); the Renderer sets
  // them once. It opens a scope around each pass's prepare() and execute(): inside it, a pass may touch
  // a shared resource (texture(), markWritten()) only as its `access` declares, and execute() may
  // allocate nothing (a texture, buffer or framebuffer created there throws). A breach is a
  // programmer error: std::logic_error naming the pass, the resource and what it declared. Names that
  // are not shared (a pass's own intermediate targets) are the pass's business.
  enum class Phase { Prepare, Execute };
  void setSharedResources(std::set<std::string> names) { shared_ = std::move(names); }
  bool isShared(const std::string& name) const { return shared_.count(name) != 0; }
  void beginPass(std::string pass, std::vector<ResourceAccess> access, Phase phase);
  void endPass() { pass_.clear(); inPass_ = false; }
  // What the current pass marked written (the Renderer checks these against its declared outputs).
  const std::set<std::string>& passWrites() const { return passWrites_; }

  // Cached derived data: returns the entry under `key` if it was built from `inputsDigest`, else
  // builds it with `build` and stores it. Logs "key" as a hit or a miss.
  template <class T>
  T& cached(const std::string& key, const std::string& inputsDigest, const std::function<std::unique_ptr<T>()>& build) {
    Family& entries = cache_[key];  // by inputs digest
    const bool hit = entries.use(inputsDigest) != nullptr;
    if (cacheLog_) cacheLog_->push_back({key, hit});
    if (!hit) {
      auto value = build();
      T* raw = value.release();
      std::function<std::size_t()> bytes;
      if constexpr (requires(const T& v) { { v.bytes() } -> std::convertible_to<std::size_t>; })
        bytes = [raw] { return static_cast<std::size_t>(raw->bytes()); };
      entries.put(inputsDigest,
                  Entry{std::shared_ptr<void>(raw, [](void* p) { delete static_cast<T*>(p); }), std::move(bytes), frame_});
      entries.evict([&](const Family& f) { return f.size() > derivedCapacity_; });
      keepWithinDerivedBytes();  // on insertion only: a budget below one set still reuses the set in use
    }
    Entry& e = entries.begin()->value;  // the most recently used: this one
    e.frame = frame_;
    return *static_cast<T*>(e.value.get());
  }
  // Bytes the sized derived data may hold together (at least one entry is always kept: the one in use).
  void setDerivedBytes(std::size_t bytes) {
    derivedBytes_ = bytes;
    keepWithinDerivedBytes();
  }
  // The sized derived data's bytes now (photon sets grow as requests refine them).
  std::size_t derivedBytes() const;
  // Digests kept per cache key (at least 1; default 4).
  void setDerivedCapacity(std::size_t n) {
    derivedCapacity_ = n < 1 ? 1 : n;
    for (auto& [key, entries] : cache_) entries.evict([&](const Family& f) { return f.size() > derivedCapacity_; });
  }
  // Drops every cached entry and resource (after a GL failure the objects may be invalid).
  void clear();

  // One memory accountant (issue 30): the process's resident set is kept under a target (radiantd
  // --memory-target-bytes). A pass about to allocate much (photon records, splat grids) calls
  // makeRoom() with its estimate first: when the resident set plus the estimate exceed the target, what
  // this frame has not used goes (release below), and the Renderer's hook (the GPU scenes of other
  // scenes). The Renderer calls it with 0 after each frame, so the resident set at rest stays under the
  // target too. Returns the bytes the resident set shrank by (0 when nothing was needed).
  std::size_t makeRoom(std::size_t bytes);
  // After a frame (the Renderer, however the frame ended): makeRoom(0), and when the frame's own
  // textures and buffers still leave the resident set above the memory limit (a 1920 x 1080 frame at
  // supersampling 2 holds 1.9 GB on llvmpipe), they go too, so that the daemon at rest is under its
  // limit: otherwise every later request body and decode would be refused (503 memory-busy) with no
  // frame running that could free them. Cached derived data of this frame stays. Returns the bytes
  // the resident set shrank by.
  std::size_t settleAfterFrame();
  // Admission under the memory limit (radiantd --memory-limit-bytes, 0 = none): after makeRoom, an
  // estimate that still does not fit under it is refused, a 503 memory-busy (Retry-After) naming
  // `pointer`, the parameter that sized the allocation, before anything is allocated. An admitted
  // estimate is claimed process-wide (MemoryClaims, renderer/ResidentMemory.h) until the next admission
  // of the frame replaces it or releaseClaim(), so concurrent decodes and request bodies see it.
  void admit(std::size_t bytes, const std::string& pointer);
  // Lets the frame's claim go (the Renderer, when the frame ends however it ends).
  void releaseClaim();
  void setMemoryLimit(std::size_t bytes) { memoryLimit_ = bytes; }
  std::size_t memoryLimit() const { return memoryLimit_; }
  // What declaring this texture would allocate: 0 when it exists with this spec, else its bytes.
  std::size_t textureAllocation(const std::string& name, GLenum target, GLenum internalFormat, int width, int height,
                                int depth = 1, int levels = 1) const;
  std::size_t releasedThisFrame() const { return releasedThisFrame_; }
  void setMemoryTarget(std::size_t bytes) { memoryTarget_ = bytes; }
  std::size_t memoryTarget() const { return memoryTarget_; }
  void setTrimHook(std::function<void()> hook) { trimHook_ = std::move(hook); }
  // Releases every texture, buffer and framebuffer this frame has not used and every cached entry of an
  // earlier frame (what they held is forgotten: the next frame that needs them rebuilds them), then
  // gives the freed heap back to the system.
  void releaseIdle();
  // Bytes of the textures and buffers (estimated from their formats and sizes; on a GPU they are
  // device memory, on llvmpipe host memory).
  std::size_t resourceBytes() const;
  // The process's resident set (Linux /proc/self/statm; 0 where unavailable).
  static std::size_t residentBytes();

private:
  rt::Cancel cancel_;
  struct TextureSpec {
    GLenum target, format;
    int width, height, depth, levels;
    bool operator==(const TextureSpec&) const = default;
  };
  struct Entry {
    std::shared_ptr<void> value;
    std::function<std::size_t()> bytes;  // empty: the type does not report its size
    std::uint64_t frame = 0;             // the last frame that looked it up
  };
  // Drops the least recently used sized entries of earlier frames until derivedBytes() <= derivedBytes_.
  void keepWithinDerivedBytes();
  std::uint64_t frame_ = 0;  // beginFrame() counts
  std::size_t derivedBytes_ = std::size_t(1) << 40;
  gl::ShaderLibrary& shaders_;
  const GpuScene* gpu_ = nullptr;
  const FrameView* view_ = nullptr;
  std::vector<api::CacheEvent>* cacheLog_ = nullptr;
  std::map<std::string, std::pair<TextureSpec, gl::Texture>> textures_;
  std::map<std::string, gl::Framebuffer> framebuffers_;
  std::map<std::string, gl::Buffer> buffers_;
  gl::Buffer frameConstants_;  // the view's gpu::FrameConstants, bound at kBindingFrameConstants (beginFrame)
  using Family = api::Lru<std::string, Entry>;  // one cache key's entries, by inputs digest
  std::map<std::string, Family> cache_;
  std::map<std::string, std::string> holds_;  // resource -> digest of what it holds (refill())
  std::size_t derivedCapacity_ = 4;
  std::set<std::string> written_;
  std::map<std::string, std::vector<Composition>> compositions_;  // accumulate(), cleared by beginFrame()
  std::map<std::string, std::any> products_;  // the blackboard, cleared by beginFrame()
  std::map<std::string, std::string> lightPaths_;
  std::map<std::string, api::LightPathMask> owned_;
  std::set<std::string> declaredThisFrame_;
  // Textures, buffers and framebuffers looked up or declared this frame (releaseIdle keeps them).
  mutable std::set<std::string> usedThisFrame_;
  void used(const std::string& name) const { usedThisFrame_.insert(name); }
  std::size_t memoryTarget_ = std::size_t(1) << 40;
  std::size_t releasedThisFrame_ = 0;
  std::size_t memoryLimit_ = 0;
  std::size_t claim_ = 0;  // admit(): the frame's claim in MemoryClaims
  std::function<void()> trimHook_;
  std::set<std::string> passWrites_;
  // The current pass scope (beginPass / endPass): what it declares of `name` (nullptr: nothing).
  const ResourceAccess* declaration(const std::string& name) const;
  void checkAccess(const std::string& name, bool write) const;
  void checkNoAllocation(const std::string& what, const std::string& name) const;
  std::set<std::string> shared_;
  bool inPass_ = false;
  std::string pass_;
  std::vector<ResourceAccess> access_;
  Phase phase_ = Phase::Prepare;
};

}  // namespace radiant
