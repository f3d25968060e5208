// The G-buffer's attachments as readers see them (renderer/shading/GBufferInputs.h): the one table of
// their resource names, formats and units agrees with what the gbuffer technique declares
// (renderer/techniques/gbuffer/gbuffer.json) and with the AOV table, and the units are the common
// programs' (shaders/common/shared.h), one per attachment.
#include <algorithm>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "api/Aovs.h"
#include "renderer/frame/GpuTypes.h"
#include "renderer/frame/Technique.h"
#include "renderer/shading/GBufferInputs.h"

namespace radiant {
namespace {

GLenum glFormat(api::AovFormat f) {
  switch (f) {
    case api::AovFormat::Rgba32F: return GL_RGBA32F;
    case api::AovFormat::Rgba16F: return GL_RGBA16F;
    case api::AovFormat::R32F: return GL_R32F;
  }
  return 0;
}

TEST(GBufferInputs, EveryAttachmentIsWhatTheGBufferDeclaresInTheAovTablesFormat) {
  const TechniqueInfo g = describedTechnique("gbuffer");
  std::set<std::string> names;
  for (gbuffer::Attachment a : gbuffer::kAttachments) {
    const std::string name = gbuffer::name(a);
    EXPECT_TRUE(names.insert(name).second) << name << " twice";
    EXPECT_NE(std::find(g.outputs.begin(), g.outputs.end(), name), g.outputs.end())
        << name << " is not among the gbuffer technique's outputs and resources";
    // Where an AOV reads the attachment, the table's format is the attachment's (FrameResources refuses
    // a declaration in another format at run time; this says which table is wrong).
    for (const api::AovInfo& aov : api::aovTable())
      if (aov.resource == name) {
        EXPECT_EQ(glFormat(aov.format), gbuffer::format(a)) << aov.name;
      }
  }
  // What the gbuffer writes besides its depth buffer is exactly these attachments (its colour targets).
  std::set<std::string> written;
  for (const std::string& out : g.outputs) {
    const api::AovInfo* aov = api::findAov(out);
    written.insert(aov ? aov->resource : out);
  }
  written.erase("depth_buffer");
  EXPECT_EQ(written, names);
  EXPECT_EQ(gbuffer::format(gbuffer::Attachment::Layers), static_cast<GLenum>(GL_RGBA32UI));  // cleared as integers
}

TEST(GBufferInputs, EachAttachmentHasItsOwnUnitAndTheFirstSixAreTheFullScreenUnits) {
  std::set<GLuint> units;
  for (gbuffer::Attachment a : gbuffer::kAttachments) {
    EXPECT_TRUE(units.insert(gbuffer::unit(a)).second) << gbuffer::name(a);
    EXPECT_LT(gbuffer::unit(a), static_cast<GLuint>(gpu::kUnitCount));
  }
  // Units 0-5 are the full-screen inputs (below kUnitShadowCube); the layers and specular targets have
  // frame-wide units of their own.
  for (int i = 0; i < 6; ++i) EXPECT_EQ(gbuffer::unit(gbuffer::kAttachments[i]), static_cast<GLuint>(i));
  EXPECT_GE(gbuffer::unit(gbuffer::Attachment::Layers), static_cast<GLuint>(gpu::kUnitShadowCube));
  EXPECT_GE(gbuffer::unit(gbuffer::Attachment::Specular), static_cast<GLuint>(gpu::kUnitShadowCube));
}

}  // namespace
}  // namespace radiant
