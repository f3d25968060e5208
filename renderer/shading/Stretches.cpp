#include "renderer/shading/Stretches.h"

#include <algorithm>

namespace radiant {

void drawInstancedInStretches(const gl::Program& prog, GLenum mode, int vertices, int instances, int perStretch,
                              const rt::Cancel& cancel, std::string_view where) {
  perStretch = std::max(1, perStretch);
  // One stretch in flight while the next is issued (StretchGate): without the wait a driver that
  // defers fragment work (llvmpipe) takes every stretch's draw call at once and the checks all pass
  // before the flag: a spherical_billboards frame ran 5 s past it.
  StretchGate gate(cancel);
  try {
    for (int first = 0; first < instances; first += perStretch) {
      if (first > 0) gate.check(where);
      prog.set("u_firstInstance", first);
      glDrawArraysInstanced(mode, 0, vertices, std::min(perStretch, instances - first));
      if (first + perStretch < instances) gate.issued();
    }
  } catch (const rt::Cancelled&) {
    prog.set("u_firstInstance", 0);
    throw;
  }
  prog.set("u_firstInstance", 0);
}

StretchGate::~StretchGate() {
  if (previous_) glDeleteSync(previous_);
}

void StretchGate::check(std::string_view where) {
  if (previous_) {
    glClientWaitSync(previous_, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(60) * 1000000000);
    glDeleteSync(previous_);
    previous_ = nullptr;
  }
  cancel_.check(where);
}

void StretchGate::issued() {
  if (!cancel_.flag()) return;  // nothing can cancel this request: never wait
  if (previous_) glDeleteSync(previous_);
  previous_ = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
}

}  // namespace radiant
