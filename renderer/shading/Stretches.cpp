#include "renderer/shading/Stretches.h"

#include <algorithm>

namespace radiant {

void drawInstancedInStretches(const gl::Program& prog, GLenum mode, int vertices, int instances, int perStretch,
                              const rt::Cancel& cancel, std::string_view where) {
  perStretch = std::max(1, perStretch);
  for (int first = 0; first < instances; first += perStretch) {
    if (first > 0 && cancel.requested()) {
      prog.set("u_firstInstance", 0);
      cancel.check(where);
    }
    prog.set("u_firstInstance", first);
    glDrawArraysInstanced(mode, 0, vertices, std::min(perStretch, instances - first));
  }
  prog.set("u_firstInstance", 0);
}

}  // namespace radiant
