#include "renderer/shading/Stretches.h"

#include <algorithm>

namespace radiant {

void drawInstancedInStretches(const gl::Program& prog, GLenum mode, int vertices, int instances, int perStretch,
                              const rt::Cancel& cancel, std::string_view where) {
  perStretch = std::max(1, perStretch);
  // One stretch in flight while the next is issued: before issuing stretch k + 1 the pass waits for
  // stretch k - 1 (a fence), so the check sees the GPU's progress. Without it a driver that defers
  // fragment work (llvmpipe) takes every stretch's draw call at once and the checks all pass before the
  // flag: a spherical_billboards frame ran 5 s past it.
  GLsync previous = nullptr;
  for (int first = 0; first < instances; first += perStretch) {
    if (previous) {
      glClientWaitSync(previous, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(60) * 1000000000);
      glDeleteSync(previous);
      previous = nullptr;
    }
    if (first > 0 && cancel.requested()) {
      prog.set("u_firstInstance", 0);
      cancel.check(where);
    }
    prog.set("u_firstInstance", first);
    glDrawArraysInstanced(mode, 0, vertices, std::min(perStretch, instances - first));
    if (cancel.flag() && first + perStretch < instances) previous = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  }
  if (previous) glDeleteSync(previous);
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
