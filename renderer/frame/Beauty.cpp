#include "renderer/frame/Beauty.h"

#include <stdexcept>
#include <utility>

#include "renderer/frame/FrameResources.h"

namespace radiant {

void attachBeauty(FrameResources& res, gl::Framebuffer& fb, GLenum attachment) {
  fb.attach(attachment, res.texture(kBeauty));
}

BeautyWrite BeautyWrite::drawBuffer(FrameResources& res, GLuint drawBuffer, bool compose) {
  const GLuint i = drawBuffer;
  if (!compose) {  // nothing is composed: no declaration needed
    glColorMaski(i, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    return BeautyWrite(res, static_cast<int>(i), false);
  }
  const BeautyBlend blend = res.declaredBlend(kBeauty);
  glEnablei(GL_BLEND, i);
  glBlendEquationi(i, GL_FUNC_ADD);
  switch (blend) {
    case BeautyBlend::Add: glBlendFunci(i, GL_ONE, GL_ONE); break;
    // Beauty's alpha stays as the opaque passes left it.
    case BeautyBlend::Over: glBlendFuncSeparatei(i, GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE); break;
    case BeautyBlend::Transmit: glBlendFuncSeparatei(i, GL_ONE, GL_SRC_ALPHA, GL_ZERO, GL_ONE); break;
  }
  return BeautyWrite(res, static_cast<int>(i), true);
}

BeautyWrite BeautyWrite::image(FrameResources& res, GLuint unit) {
  const BeautyBlend blend = res.declaredBlend(kBeauty);
  if (blend != BeautyBlend::Add)
    throw std::logic_error(std::string("BeautyWrite::image: a pass that declares beauty_blend ") + toString(blend) +
                           " composes through a draw buffer (an image store is an add)");
  res.texture(kBeauty).bindImage(unit, GL_READ_WRITE);
  return BeautyWrite(res, -1, true);
}

BeautyWrite::BeautyWrite(BeautyWrite&& o) noexcept
    : res_(o.res_), drawBuffer_(o.drawBuffer_), compose_(o.compose_), open_(std::exchange(o.open_, false)) {}

void BeautyWrite::restore() {
  if (!open_) return;
  open_ = false;
  if (drawBuffer_ < 0) return;
  const GLuint i = static_cast<GLuint>(drawBuffer_);
  if (compose_) {
    glDisablei(GL_BLEND, i);
    glBlendFunci(i, GL_ONE, GL_ZERO);
  } else {
    glColorMaski(i, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }
}

BeautyWrite::~BeautyWrite() { restore(); }

void BeautyWrite::commit() {
  if (!open_) throw std::logic_error("BeautyWrite::commit: committed twice");
  restore();
  if (compose_) res_->accumulate(kBeauty);
}

}  // namespace radiant
