#pragma once
// The frame's beauty: a versioned read-modify-write resource with a declared blend (issue 33; the
// `beauty` of Filament's FrameGraph, where each write makes a new version that later passes read).
// The Renderer allocates it at zero before any pass (FrameAllocation.h); every technique that
// adds_to_beauty composes into it through a BeautyWrite, which applies the blend its descriptor declares
// (TechniqueInfo::beautyBlend, renderer/frame/BeautyBlend.h) and, on commit(), records the write as
// beauty's next version (FrameResources::accumulate, which checks the order of the blends). No pass names
// the resource or sets beauty's blend state itself, and marking beauty written directly is refused.
#include "renderer/frame/BeautyBlend.h"
#include "renderer/gl/Gl.h"

namespace radiant {

class FrameResources;

inline constexpr const char* kBeauty = "beauty";

// Attaches beauty to `fb` at `attachment` (GL_COLOR_ATTACHMENTi; a pass's prepare()). The access scope
// checks that the pass declares it (adds_to_beauty).
void attachBeauty(FrameResources& res, gl::Framebuffer& fb, GLenum attachment);

class BeautyWrite {
public:
  // A composition through draw buffer `drawBuffer` of the bound framebuffer (beauty attached there with
  // attachBeauty): while it lives, that draw buffer blends as the current pass declares
  //   Add       rgba  = src + dst
  //   Over      rgb   = a src + (1 - a) dst, alpha kept
  //   Transmit  rgb   = src + a dst (a: the medium's transmittance), alpha kept
  // With `compose` false (the pass does not own the light-path classes it would add this frame) the draw
  // buffer is masked instead, so the pass's other targets are still written, and commit() records nothing.
  static BeautyWrite drawBuffer(FrameResources& res, GLuint drawBuffer, bool compose = true);
  // A composition by a compute shader that adds into beauty itself: beauty bound as the rgba32f image
  // `unit`, read-write. Only a pass that declares Add may (a shader's imageStore is an add by contract).
  static BeautyWrite image(FrameResources& res, GLuint unit);

  BeautyWrite(BeautyWrite&& o) noexcept;
  BeautyWrite& operator=(BeautyWrite&&) = delete;
  BeautyWrite(const BeautyWrite&) = delete;
  // Restores the draw buffer's state (blend off, ONE/ZERO, colour mask on) whether or not commit() ran:
  // a pass that throws leaves no blend state behind.
  ~BeautyWrite();
  // The composition is done: restores the state and records beauty's next version (nothing when
  // `compose` was false).
  void commit();

private:
  BeautyWrite(FrameResources& res, int drawBuffer, bool compose)
      : res_(&res), drawBuffer_(drawBuffer), compose_(compose) {}
  void restore();
  FrameResources* res_;
  int drawBuffer_;  // -1: an image binding
  bool compose_;
  bool open_ = true;
};

}  // namespace radiant
