#include "renderer/shading/GBufferInputs.h"

#include <iterator>
#include <stdexcept>

#include "renderer/frame/GpuTypes.h"

namespace radiant::gbuffer {
namespace {

struct Row {
  const char* name;
  int unit;
  GLenum format;
};
// In Attachment order (the gbuffer pass's colour attachments, shaders/gbuffer/gbuffer.frag).
constexpr Row kRows[] = {
    {"gbuffer_position", gpu::kUnitGbufferPosition, GL_RGBA32F},
    {"normal", gpu::kUnitGbufferNormal, GL_RGBA16F},
    {"albedo", gpu::kUnitGbufferAlbedo, GL_RGBA16F},
    {"material", gpu::kUnitGbufferMaterial, GL_RGBA16F},
    {"emission", gpu::kUnitGbufferEmission, GL_RGBA16F},
    {"geometric_normal", gpu::kUnitGbufferGeometricNormal, GL_RGBA16F},
    // The layered extensions (docs/GBUFFER.md): clear coat, coat normal and sheen packed as halves/snorm
    // in an integer target (cleared with the integer clear), and the specular colour and weight.
    {"gbuffer_layers", gpu::kUnitGbufferLayers, GL_RGBA32UI},
    {"gbuffer_specular", gpu::kUnitGbufferSpecular, GL_RGBA16F},
};
static_assert(std::size(kRows) == std::size(kAttachments));

const Row& row(Attachment a) {
  const auto i = static_cast<std::size_t>(a);
  if (i >= std::size(kRows)) throw std::logic_error("gbuffer: no such attachment");
  return kRows[i];
}

}  // namespace

const char* name(Attachment a) { return row(a).name; }
GLuint unit(Attachment a) { return static_cast<GLuint>(row(a).unit); }
GLenum format(Attachment a) { return row(a).format; }

gl::Texture& texture(FrameResources& res, Attachment a) { return res.texture(name(a)); }

bool written(const FrameResources& res, Attachment a) { return res.hasTexture(name(a)) && res.written(name(a)); }

void bind(FrameResources& res, std::initializer_list<Attachment> attachments) {
  for (Attachment a : attachments) texture(res, a).bindUnit(unit(a));
}

void bindAt(FrameResources& res, Attachment a, GLuint u) { texture(res, a).bindUnit(u); }

}  // namespace radiant::gbuffer
