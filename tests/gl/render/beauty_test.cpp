// Beauty as a versioned read-modify-write resource with a declared blend (renderer/frame/Beauty.h): a
// BeautyWrite composes with exactly the equation its pass's descriptor declares, records each write as
// beauty's next version, refuses a composition out of the add-over-transmit order, one a pass did not
// declare and a direct markWritten, and leaves no blend state behind.
#include <array>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "renderer/frame/Beauty.h"
#include "renderer/frame/FramePlanner.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/gl/ShaderLibrary.h"
#include "tests/support/Expect.h"
#include "tests/support/RenderTestSupport.h"

namespace radiant {
namespace {

using Rgba = std::array<float, 4>;
constexpr int kSize = 4;
// What beauty holds before the composition, and what the pass draws.
constexpr Rgba kBefore = {0.25f, 0.5f, 1.f, 0.6f};
constexpr Rgba kSource = {0.5f, 0.25f, 0.125f, 0.4f};

TechniqueInfo composer(const std::string& name, BeautyBlend blend, bool addsToBeauty = true) {
  TechniqueInfo info{name, "", {}, {}, {}, addsToBeauty, false};
  info.beautyBlend = blend;
  return info;
}

class BeautyTest : public ::testing::Test {
protected:
  void SetUp() override {
    res_.setSharedResources({kBeauty});
    res_.texture(kBeauty, GL_TEXTURE_2D, GL_RGBA32F, kSize, kSize);
    glClearTexImage(res_.texture(kBeauty).id(), 0, GL_RGBA, GL_FLOAT, kBefore.data());
  }
  // A pass of `info` that attaches beauty in prepare() and draws kSource over it in execute().
  void prepare(const TechniqueInfo& info) {
    res_.beginPass(info.name, declaredAccess(info), FrameResources::Phase::Prepare);
    gl::Framebuffer& fb = res_.framebuffer("beauty_test");
    attachBeauty(res_, fb, GL_COLOR_ATTACHMENT0);
    fb.setDrawBuffers({GL_COLOR_ATTACHMENT0});
    fb.checkComplete("beauty_test");
    res_.endPass();
  }
  void draw() {
    res_.framebuffer("beauty_test").bind();
    glViewport(0, 0, kSize, kSize);
    const gl::Program& prog = shaders_.program({"common/fullscreen.vert", "tests/constant.frag"});
    prog.use();
    prog.set("u_colour", kSource.data(), 4);
    vao_.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  void compose(const TechniqueInfo& info, bool composes = true) {
    prepare(info);
    res_.beginPass(info.name, declaredAccess(info), FrameResources::Phase::Execute);
    BeautyWrite write = BeautyWrite::drawBuffer(res_, 0, composes);
    draw();
    write.commit();
    res_.endPass();
  }
  Rgba pixel() {
    std::array<float, 4 * kSize * kSize> px{};
    res_.texture(kBeauty).download(0, GL_RGBA, GL_FLOAT, px.data(), sizeof px);
    return {px[0], px[1], px[2], px[3]};
  }
  bool context_ = (testing::renderer(), true);  // a current GL context, before any GL object below
  gl::ShaderLibrary shaders_;
  FrameResources res_{shaders_};
  gl::VertexArray vao_{"beauty_test"};
};

void expectPixel(const Rgba& got, const Rgba& want, const char* what) {
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], 1e-6f) << what << " channel " << c;
}

TEST_F(BeautyTest, EachDeclaredBlendComposesAsItsEquationSays) {
  const float a = kSource[3];
  struct Case {
    BeautyBlend blend;
    Rgba want;
  };
  const Case cases[] = {
      // Add: src + dst, alpha too (the adding passes write alpha 0).
      {BeautyBlend::Add, {0.75f, 0.75f, 1.125f, 1.f}},
      // Over: a src + (1 - a) dst, alpha kept.
      {BeautyBlend::Over,
       {a * kSource[0] + (1 - a) * kBefore[0], a * kSource[1] + (1 - a) * kBefore[1],
        a * kSource[2] + (1 - a) * kBefore[2], kBefore[3]}},
      // Transmit: src + T dst with T the source's alpha, alpha kept.
      {BeautyBlend::Transmit,
       {kSource[0] + a * kBefore[0], kSource[1] + a * kBefore[1], kSource[2] + a * kBefore[2], kBefore[3]}},
  };
  for (const Case& c : cases) {
    glClearTexImage(res_.texture(kBeauty).id(), 0, GL_RGBA, GL_FLOAT, kBefore.data());
    const std::size_t before = res_.compositions(kBeauty).size();
    compose(composer(std::string("pass_") + toString(c.blend), c.blend));
    expectPixel(pixel(), c.want, toString(c.blend));
    // The write is beauty's next version, and no blend state is left behind.
    ASSERT_EQ(res_.compositions(kBeauty).size(), before + 1);
    EXPECT_EQ(res_.compositions(kBeauty).back().blend, c.blend);
    EXPECT_EQ(res_.compositions(kBeauty).back().pass, std::string("pass_") + toString(c.blend));
    EXPECT_FALSE(glIsEnabledi(GL_BLEND, 0));
  }
  EXPECT_TRUE(res_.written(kBeauty));
}

TEST_F(BeautyTest, APassThatDoesNotOwnItsClassesLeavesBeautyAndItsVersionAlone) {
  compose(composer("caustics", BeautyBlend::Add), /*composes=*/false);
  expectPixel(pixel(), kBefore, "masked");
  EXPECT_TRUE(res_.compositions(kBeauty).empty());
  EXPECT_FALSE(res_.written(kBeauty));
  GLboolean mask[4] = {};
  glGetBooleani_v(GL_COLOR_WRITEMASK, 0, mask);
  EXPECT_TRUE(mask[0] && mask[1] && mask[2] && mask[3]);  // the mask is restored
}

TEST_F(BeautyTest, CompositionsOutOfTheBlendOrderAreRefused) {
  compose(composer("direct", BeautyBlend::Add));
  compose(composer("transparency", BeautyBlend::Over));
  const std::string late = testing::thrownMessage<std::logic_error>([&] { compose(composer("late", BeautyBlend::Add)); });
  EXPECT_NE(late.find("pass late composed into 'beauty' with add after pass transparency's over"), std::string::npos)
      << late;
  EXPECT_FALSE(glIsEnabledi(GL_BLEND, 0));  // the write unwound without leaving its blend on
  res_.endPass();
  compose(composer("media", BeautyBlend::Transmit));
  ASSERT_EQ(res_.compositions(kBeauty).size(), 3u);  // the refused one is no version
  EXPECT_EQ(res_.compositions(kBeauty)[0].pass, "direct");
  EXPECT_EQ(res_.compositions(kBeauty)[2].pass, "media");
}

TEST_F(BeautyTest, UndeclaredOrDirectWritesAreRefused) {
  // A pass that does not add to beauty may not compose into it (nor attach it).
  const TechniqueInfo ao = composer("ambient_occlusion", BeautyBlend::Add, /*addsToBeauty=*/false);
  res_.beginPass(ao.name, declaredAccess(ao), FrameResources::Phase::Execute);
  const std::string undeclared = testing::thrownMessage<std::logic_error>([&] { BeautyWrite::drawBuffer(res_, 0); });
  EXPECT_NE(undeclared.find("pass ambient_occlusion composed into 'beauty'"), std::string::npos) << undeclared;
  res_.endPass();
  // One that does composes through a BeautyWrite, never by marking beauty written.
  const TechniqueInfo direct = composer("direct", BeautyBlend::Add);
  res_.beginPass(direct.name, declaredAccess(direct), FrameResources::Phase::Execute);
  const std::string marked = testing::thrownMessage<std::logic_error>([&] { res_.markWritten(kBeauty); });
  EXPECT_NE(marked.find("BeautyWrite"), std::string::npos) << marked;
  res_.endPass();
  // An image store adds: a pass declaring another blend composes through a draw buffer.
  const TechniqueInfo glass = composer("glass", BeautyBlend::Over);
  res_.beginPass(glass.name, declaredAccess(glass), FrameResources::Phase::Execute);
  const std::string image = testing::thrownMessage<std::logic_error>([&] { BeautyWrite::image(res_, 1); });
  EXPECT_NE(image.find("over"), std::string::npos) << image;
  res_.endPass();
  EXPECT_TRUE(res_.compositions(kBeauty).empty());
  EXPECT_FALSE(res_.written(kBeauty));
  // Outside a pass scope there is no declaration to compose with.
  EXPECT_THROW(BeautyWrite::drawBuffer(res_, 0), std::logic_error);
}

}  // namespace
}  // namespace radiant
