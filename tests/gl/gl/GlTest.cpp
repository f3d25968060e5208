// renderer/gl/Gl: the RAII wrappers, against a real context (Mesa llvmpipe in CI).
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "tests/support/Expect.h"
#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/platform/EglDevice.h"

namespace radiant::gl {
namespace {

class GlTest : public ::testing::Test {
protected:
  void SetUp() override { device_ = EglDevice::create(); }
  void TearDown() override {
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << "a test left a GL error behind";
  }
  std::unique_ptr<EglDevice> device_;
};

std::string objectLabel(GLenum identifier, GLuint id) {
  char buf[256] = {};
  GLsizei n = 0;
  glGetObjectLabel(identifier, id, sizeof buf, &n, buf);
  return std::string(buf, static_cast<std::size_t>(n));
}


TEST_F(GlTest, CheckErrorNamesTheCallAndDrains) {
  EXPECT_NO_THROW(checkError("idle"));
  // GL may keep one flag per error kind or, like Mesa, only the first error until glGetError
  // (GL 4.5 core section 2.3.1); either way the first one is reported and nothing is left over.
  glEnable(0xFFFF);                                  // GL_INVALID_ENUM
  glBindBufferBase(GL_UNIFORM_BUFFER, 1u << 30, 0);  // GL_INVALID_VALUE
  const std::string message = testing::thrownMessage<GlError>([] { checkError("CheckErrorTest"); });
  EXPECT_EQ(message.rfind("CheckErrorTest: GL_INVALID_ENUM", 0), 0u) << message;
  EXPECT_NO_THROW(checkError("after drain"));
  EXPECT_STREQ(errorName(GL_OUT_OF_MEMORY), "GL_OUT_OF_MEMORY");
}

TEST_F(GlTest, ObjectsCarryTheirLabels) {
  Buffer buffer("test.buffer", 64);
  Texture texture("test.texture", GL_TEXTURE_2D, GL_RGBA16F, 4, 4);
  Framebuffer framebuffer("test.framebuffer");
  VertexArray vertexArray("test.vao");
  TimerQuery query("test.query");
  EXPECT_EQ(objectLabel(GL_BUFFER, buffer.id()), "test.buffer");
  EXPECT_EQ(objectLabel(GL_TEXTURE, texture.id()), "test.texture");
  EXPECT_EQ(objectLabel(GL_FRAMEBUFFER, framebuffer.id()), "test.framebuffer");
  EXPECT_EQ(objectLabel(GL_VERTEX_ARRAY, vertexArray.id()), "test.vao");
  EXPECT_EQ(objectLabel(GL_QUERY, query.id()), "test.query");

  // Longer than GL_MAX_LABEL_LENGTH: clipped rather than a GL_INVALID_VALUE.
  const std::string longLabel(5000, 'x');
  Buffer longBuffer(longLabel, 16);
  EXPECT_EQ(objectLabel(GL_BUFFER, longBuffer.id()).substr(0, 10), "xxxxxxxxxx");
  EXPECT_NO_THROW(checkError("long label"));
}

TEST_F(GlTest, MoveTransfersOwnershipAndAssignmentReleasesTheOld) {
  Buffer a("a", 16);
  const GLuint aId = a.id();
  Buffer b(std::move(a));
  EXPECT_EQ(a.id(), 0u);
  EXPECT_FALSE(a);
  EXPECT_EQ(b.id(), aId);
  EXPECT_EQ(b.size(), 16u);

  Buffer c("c", 32);
  const GLuint cId = c.id();
  c = std::move(b);
  EXPECT_EQ(c.id(), aId);
  EXPECT_EQ(b.id(), 0u);
  EXPECT_FALSE(glIsBuffer(cId)) << "move assignment must delete the buffer it replaced";
  EXPECT_TRUE(glIsBuffer(aId));

  Texture t1("t1", GL_TEXTURE_2D, GL_RGBA8, 2, 2);
  Texture t2("t2", GL_TEXTURE_2D, GL_RGBA8, 2, 2);
  const GLuint t1Id = t1.id(), t2Id = t2.id();
  t2 = std::move(t1);
  EXPECT_EQ(t1.id(), 0u);
  EXPECT_EQ(t2.id(), t1Id);
  EXPECT_EQ(t2.width(), 2);
  EXPECT_FALSE(glIsTexture(t2Id));

  Framebuffer f1("f1"), f2("f2");
  const GLuint f2Id = f2.id();
  f2 = std::move(f1);
  EXPECT_EQ(f1.id(), 0u);
  EXPECT_FALSE(glIsFramebuffer(f2Id));

  VertexArray v1("v1"), v2("v2");
  const GLuint v2Id = v2.id();
  v2 = std::move(v1);
  EXPECT_EQ(v1.id(), 0u);
  EXPECT_FALSE(glIsVertexArray(v2Id));

  TimerQuery q1("q1"), q2("q2");
  const GLuint q2Id = q2.id();
  q2 = std::move(q1);
  EXPECT_EQ(q1.id(), 0u);
  EXPECT_FALSE(glIsQuery(q2Id));

  Program p1(glCreateProgram(), "p1"), p2(glCreateProgram(), "p2");
  const GLuint p1Id = p1.id(), p2Id = p2.id();
  p2 = std::move(p1);
  EXPECT_EQ(p1.id(), 0u);
  EXPECT_EQ(p2.id(), p1Id);
  EXPECT_EQ(p2.label(), "p1");
  EXPECT_FALSE(glIsProgram(p2Id));

  {
    Buffer scoped("scoped", 8);
    const GLuint id = scoped.id();
    Buffer moved(std::move(scoped));
    EXPECT_TRUE(glIsBuffer(id));
  }
  Buffer empty;
  empty = Buffer("late", 8);  // assigning into an empty handle deletes nothing
  EXPECT_TRUE(empty);
}

TEST_F(GlTest, BufferRoundTripAndBoundsCheck) {
  std::vector<std::uint32_t> data(1000);
  for (std::size_t i = 0; i < data.size(); ++i)
    data[i] = static_cast<std::uint32_t>(i * 2654435761u);
  Buffer buffer("roundtrip", data.size() * 4, data.data());
  std::vector<std::uint32_t> back(data.size());
  buffer.download(back.data(), back.size() * 4);
  EXPECT_EQ(back, data);

  const std::uint32_t patch[2] = {7, 9};
  buffer.upload(patch, sizeof patch, 40);
  std::uint32_t got[2] = {};
  buffer.download(got, sizeof got, 40);
  EXPECT_EQ(got[0], 7u);
  EXPECT_EQ(got[1], 9u);
  EXPECT_THROW(buffer.upload(patch, sizeof patch, 4000 - 4), std::out_of_range);
  EXPECT_THROW(Buffer("empty", 0), std::invalid_argument);
}

TEST_F(GlTest, TextureRgba32fRoundTripsExactly) {
  // Odd sizes catch row-alignment mistakes; the values are ones a lossy path would change.
  const int w = 7, h = 5;
  std::vector<float> pixels(static_cast<std::size_t>(w * h * 4));
  const float specials[] = {-0.0f,   1e-30f,       65504.5f,
                            3.0e38f, -1.0f / 3.0f, std::numeric_limits<float>::denorm_min(),
                            0.1f};
  for (std::size_t i = 0; i < pixels.size(); ++i)
    pixels[i] =
        i < std::size(specials) ? specials[i] : std::ldexp(float(i) + 0.3f, int(i % 41) - 20);
  Texture texture("rgba32f", GL_TEXTURE_2D, GL_RGBA32F, w, h);
  texture.upload(0, 0, 0, 0, w, h, 1, GL_RGBA, GL_FLOAT, pixels.data());
  std::vector<float> back(pixels.size(), 42.0f);
  texture.download(0, GL_RGBA, GL_FLOAT, back.data(), back.size() * sizeof(float));
  EXPECT_EQ(std::memcmp(back.data(), pixels.data(), pixels.size() * sizeof(float)), 0);
  for (std::size_t i = 0; i < pixels.size(); ++i)
    ASSERT_EQ(std::memcmp(&back[i], &pixels[i], sizeof(float)), 0) << "component " << i;
}

TEST_F(GlTest, CubeMapFacesAreAddressedByZ) {
  const int size = 4;
  Texture cube("cube", GL_TEXTURE_CUBE_MAP, GL_RGBA32F, size, size);
  std::vector<float> all(static_cast<std::size_t>(6 * size * size * 4));
  for (int face = 0; face < 6; ++face) {
    std::vector<float> pixels(static_cast<std::size_t>(size * size * 4), float(face) + 0.5f);
    cube.upload(0, 0, 0, face, size, size, 1, GL_RGBA, GL_FLOAT, pixels.data());
  }
  cube.download(0, GL_RGBA, GL_FLOAT, all.data(), all.size() * sizeof(float));
  for (int face = 0; face < 6; ++face)
    EXPECT_EQ(all[static_cast<std::size_t>(face * size * size * 4 + 5)], float(face) + 0.5f);
}

TEST_F(GlTest, TextureDownloadRefusesTooSmallBuffer) {
  Texture texture("small", GL_TEXTURE_2D, GL_RGBA32F, 4, 4);
  std::vector<float> out(4);
  const std::string message = testing::thrownMessage<GlError>(
      [&] { texture.download(0, GL_RGBA, GL_FLOAT, out.data(), out.size() * sizeof(float)); });
  EXPECT_NE(message.find("Texture::download: GL_INVALID_OPERATION"), std::string::npos) << message;
}

TEST_F(GlTest, IncompleteFramebufferThrowsNamingTheStatus) {
  Framebuffer empty("empty");
  const std::string missing = testing::thrownMessage<GlError>([&] { empty.checkComplete("EmptyTest"); });
  EXPECT_EQ(missing,
            "EmptyTest: framebuffer incomplete: GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT");

  // A colour format on the depth attachment is not depth-renderable (GL 4.5 core section 9.4.1).
  Texture colour("colour", GL_TEXTURE_2D, GL_RGBA8, 4, 4);
  Framebuffer wrong("wrong");
  wrong.attach(GL_DEPTH_ATTACHMENT, colour);
  const std::string attachment = testing::thrownMessage<GlError>([&] { wrong.checkComplete("WrongTest"); });
  EXPECT_NE(attachment.find("GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT"), std::string::npos)
      << attachment;

  Framebuffer good("good");
  good.attach(GL_COLOR_ATTACHMENT0, colour);
  EXPECT_NO_THROW(good.checkComplete("GoodTest"));

  // Layered and single-layer attachment of an array texture.
  Texture array("array", GL_TEXTURE_2D_ARRAY, GL_RGBA16F, 4, 4, 3);
  Framebuffer layered("layered"), layer("layer");
  layered.attach(GL_COLOR_ATTACHMENT0, array);
  layer.attach(GL_COLOR_ATTACHMENT0, array, 0, 2);
  EXPECT_NO_THROW(layered.checkComplete("LayeredTest"));
  EXPECT_NO_THROW(layer.checkComplete("LayerTest"));
}

TEST_F(GlTest, ComputeShaderWritesSsboExactly) {
  ShaderLibrary library;
  const Program& program = library.program({"tests/fill.comp"}, {{"OFFSET", "7"}});
  const int count = 1000;
  Buffer values("values", count * sizeof(std::uint32_t));
  Buffer constants("constants", 2 * sizeof(float));
  values.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  constants.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  program.use();
  program.set("count", count);
  glDispatchCompute((count + 63) / 64, 1, 1);
  // SSBO writes become visible to glGetBufferSubData only after this barrier (GL 4.5 core 7.12.2).
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  checkError("dispatch fill.comp");

  std::vector<std::uint32_t> got(count);
  values.download(got.data(), got.size() * sizeof(std::uint32_t));
  for (int i = 0; i < count; ++i)
    ASSERT_EQ(got[static_cast<std::size_t>(i)], std::uint32_t(i * 3 + 7)) << i;
  float c[2] = {};
  constants.download(c, sizeof c);
  EXPECT_EQ(c[0], 3.14159265358979323846f);  // common/constants.glsl PI, through two includes
  EXPECT_FLOAT_EQ(c[1], 1.0f);
}

TEST_F(GlTest, TimerQueryMeasuresDispatch) {
  ShaderLibrary library;
  const Program& program = library.program({"tests/busy.comp"});
  const int invocations = 64 * 256;
  Buffer result("busy.result", invocations * sizeof(float));
  result.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  program.use();
  program.set("iterations", 200);
  // llvmpipe runs compute synchronously outside its binned scene, so it times a dispatch as ~1 ns;
  // hardware drivers report the real duration. Either way: positive and within the CPU interval.
  TimerQuery query("busy.timer");
  const auto cpuStart = std::chrono::steady_clock::now();
  query.begin();
  glDispatchCompute(invocations / 64, 1, 1);
  query.end();
  glFinish();
  EXPECT_TRUE(query.resultAvailable());
  const std::uint64_t ns = query.resultNs();
  const auto cpuNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::steady_clock::now() - cpuStart)
                         .count();
  EXPECT_GT(ns, 0u);
  EXPECT_LE(ns, static_cast<std::uint64_t>(cpuNs));
  std::fprintf(stderr, "busy.comp: %llu ns\n", static_cast<unsigned long long>(ns));
}

TEST_F(GlTest, TimerQueryMeasuresDraw) {
  ShaderLibrary library;
  const Program& program = library.program({"tests/triangle.vert", "tests/triangle.frag"});
  // A full-screen quad (two indexed triangles) with interleaved position + colour.
  // clang-format off
  const float vertices[] = {-1, -1,  1, 0, 0,
                             1, -1,  0, 1, 0,
                             1,  1,  0, 0, 1,
                            -1,  1,  1, 1, 1};
  // clang-format on
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  Buffer vbo("quad.vertices", sizeof vertices, vertices);
  Buffer ibo("quad.indices", sizeof indices, indices);
  VertexArray vao("quad");
  vao.attribute(0, 0, vbo, 2, 5 * sizeof(float), 0);
  vao.attribute(1, 1, vbo, 3, 5 * sizeof(float), 2 * sizeof(float));
  vao.elements(ibo);

  const int size = 256;
  Texture target("quad.target", GL_TEXTURE_2D, GL_RGBA32F, size, size);
  Framebuffer fbo("quad.fbo");
  fbo.attach(GL_COLOR_ATTACHMENT0, target);
  fbo.setDrawBuffers({GL_COLOR_ATTACHMENT0});
  fbo.checkComplete("quad.fbo");
  fbo.bind();
  glViewport(0, 0, size, size);
  program.use();
  vao.bind();

  // This is the context's first query and first draw: the case llvmpipe gets wrong without the
  // warm-up in EglDevice::create(). The GPU interval lies inside the CPU interval from begin() to
  // the result's return, which bounds it from above.
  TimerQuery query("quad.timer");
  const auto cpuStart = std::chrono::steady_clock::now();
  {
    DebugGroup group("quad draw");
    query.begin();
    for (int i = 0; i < 20; ++i) glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, nullptr);
    query.end();
  }
  const std::uint64_t ns = query.resultNs();
  const auto cpuNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::steady_clock::now() - cpuStart)
                         .count();
  EXPECT_GT(ns, 0u);
  EXPECT_LE(ns, static_cast<std::uint64_t>(cpuNs));
  std::fprintf(stderr, "20 full-screen quads at %dx%d: %.3f ms\n", size, size, double(ns) * 1e-6);
  checkError("quad draw");

  std::vector<float> pixels(static_cast<std::size_t>(size * size * 4));
  target.download(0, GL_RGBA, GL_FLOAT, pixels.data(), pixels.size() * sizeof(float));
  // Bottom-left corner is vertex 0 (red); the centre mixes all four colours.
  EXPECT_GT(pixels[0], 0.95f);
  EXPECT_LT(pixels[1], 0.05f);
  EXPECT_EQ(pixels[3], 1.0f);
  const std::size_t centre = static_cast<std::size_t>((size / 2 * size + size / 2) * 4);
  EXPECT_GT(pixels[centre + 2], 0.2f);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

TEST_F(GlTest, ProgramUniformHelpersIgnoreAbsentNames) {
  ShaderLibrary library;
  const Program& program = library.program({"tests/busy.comp"});
  EXPECT_EQ(program.uniformLocation("noSuchUniform"), -1);
  EXPECT_GE(program.uniformLocation("iterations"), 0);
  const float v[4] = {1, 2, 3, 4};
  program.set("noSuchUniform", 1);
  program.set("noSuchUniform", 1.0f);
  program.set("noSuchUniform", v, 3);
  program.setMat4("noSuchUniform", v);
  checkError("absent uniforms");
}

TEST_F(GlTest, TextureStateCallsAreValid) {
  Texture image("image", GL_TEXTURE_2D, GL_RGBA32F, 4, 4);
  image.bindImage(0, GL_WRITE_ONLY);
  image.bindUnit(0);
  image.setWrap(GL_CLAMP_TO_EDGE);
  image.setFilter(GL_NEAREST, GL_NEAREST);
  Texture depth("depth", GL_TEXTURE_2D, GL_DEPTH_COMPONENT32F, 4, 4);
  depth.setCompare(GL_GREATER);  // reversed-Z
  Texture mipmapped("mipmapped", GL_TEXTURE_2D, GL_RGBA16F, 8, 8, 1, 4);
  mipmapped.generateMipmaps();
  EXPECT_EQ(mipmapped.levels(), 4);
  Texture cubeArray("cubeArray", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA16F, 4, 4, 12);
  EXPECT_EQ(cubeArray.depth(), 12);
  EXPECT_THROW(Texture("badCubeArray", GL_TEXTURE_CUBE_MAP_ARRAY, GL_RGBA16F, 4, 4, 7),
               std::invalid_argument);
  checkError("image/texture state");
}

}  // namespace
}  // namespace radiant::gl
