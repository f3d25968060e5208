#pragma once
// Long GPU work in stretches with a cancel check between them (renderer/raytracing/Cancel.h): a
// cancelled, timed-out or shut-down request stops after the stretch in flight, not after the draw.
// A stretch is waited for (a fence) only when the next but one is issued, so the GPU is never idle.
#include <string_view>

#include "renderer/gl/Gl.h"
#include "renderer/raytracing/Cancel.h"

namespace radiant {

// Draws `instances` instances of `vertices` vertices (`mode`) in order, `perStretch` instances at a
// time (blending order is kept), checking `cancel` between stretches. The vertex shader reads its
// instance as u_firstInstance + gl_InstanceID (gl_InstanceID does not count the base instance); the
// uniform is 0 again afterwards, also when cancelled, for the program's other users.
void drawInstancedInStretches(const gl::Program& prog, GLenum mode, int vertices, int instances, int perStretch,
                              const rt::Cancel& cancel, std::string_view where);

// The same for a loop of GPU work that is not one instanced draw (a cube map's faces, a face's
// dispatches): call check() before issuing each stretch and issued() after it. check() waits for the
// stretch issued last (a fence, only while the request can be cancelled) and throws rt::Cancelled
// naming `where` when the flag is up.
class StretchGate {
public:
  explicit StretchGate(const rt::Cancel& cancel) : cancel_(cancel) {}
  StretchGate(const StretchGate&) = delete;
  StretchGate& operator=(const StretchGate&) = delete;
  ~StretchGate();
  void check(std::string_view where);
  void issued();

private:
  const rt::Cancel& cancel_;
  GLsync previous_ = nullptr;
};

}  // namespace radiant
