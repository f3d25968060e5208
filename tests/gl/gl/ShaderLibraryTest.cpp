// renderer/gl/ShaderLibrary: preprocessing of embedded shaders, error locations, program cache.
// The fixtures live in shaders/tests/.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "tests/support/Expect.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/platform/EglDevice.h"

namespace radiant::gl {
namespace {

class ShaderLibraryTest : public ::testing::Test {
protected:
  void SetUp() override { device_ = EglDevice::create(); }
  std::unique_ptr<EglDevice> device_;
};

// 1-based line of the first line of embedded file `name` that contains `needle`.
int lineOf(std::string_view name, std::string_view needle) {
  const std::string_view src = ShaderLibrary::source(name);
  const std::size_t at = src.find(needle);
  EXPECT_NE(at, std::string_view::npos) << needle << " not in " << name;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += src[i] == '\n';
  return line;
}


TEST(ShaderLibraryPreprocess, VersionFirstThenDefinesThenExpandedIncludes) {
  const std::string text =
      ShaderLibrary::preprocess("tests/fill.comp", {{"OFFSET", "7"}, {"FLAG", ""}});
  EXPECT_EQ(text.rfind("#version 450 core\n", 0), 0u) << text;
  const std::size_t offset = text.find("#define OFFSET 7\n");
  const std::size_t flag = text.find("#define FLAG\n");
  const std::size_t constants = text.find("const float PI = 3.14159265358979323846;");
  const std::size_t helper = text.find("float includeOk()");
  const std::size_t main = text.find("void main()");
  ASSERT_NE(offset, std::string::npos) << text;
  ASSERT_NE(flag, std::string::npos) << text;
  ASSERT_NE(constants, std::string::npos) << text;
  ASSERT_NE(helper, std::string::npos) << text;
  ASSERT_NE(main, std::string::npos) << text;
  EXPECT_LT(offset, constants);
  EXPECT_LT(constants, helper);  // nested include expands in place
  EXPECT_LT(helper, main);
  EXPECT_EQ(text.find("\n#include"), std::string::npos) << text;
  EXPECT_EQ(text.find("#version", 1), std::string::npos);
  // Each file is announced with its source-string number; after the include, fill.comp resumes
  // at the line following its #include.
  // File k's lines are numbered from k * 100000 + 1 (see kLineStride in ShaderLibrary.cpp).
  EXPECT_NE(text.find("#line 1 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("#line 100001 1\n#define OFFSET 7"), std::string::npos) << text;
  EXPECT_NE(text.find("#line 200001 2\n"), std::string::npos) << text;
  EXPECT_NE(
      text.find("#line " + std::to_string(lineOf("tests/fill.comp", "#include") + 1) + " 0\n"),
      std::string::npos)
      << text;
}

TEST(ShaderLibraryPreprocess, RejectsCyclesMissingFilesAndBadDefines) {
  const std::string cycle =
      testing::thrownMessage<GlError>([] { ShaderLibrary::preprocess("tests/include_cycle_a.glsl", {}); });
  EXPECT_NE(cycle.find("#include cycle: tests/include_cycle_a.glsl -> tests/include_cycle_b.glsl "
                       "-> tests/include_cycle_a.glsl"),
            std::string::npos)
      << cycle;
  EXPECT_EQ(cycle.rfind("shaders/tests/include_cycle_b.glsl:2: ", 0), 0u) << cycle;

  const std::string missing = testing::thrownMessage<GlError>([] { ShaderLibrary::source("tests/nope.frag"); });
  EXPECT_NE(missing.find("\"tests/nope.frag\""), std::string::npos) << missing;

  EXPECT_THROW(ShaderLibrary::preprocess("tests/fill.comp", {{"1BAD", "1"}}), GlError);
  EXPECT_THROW(ShaderLibrary::preprocess("tests/fill.comp", {{"X", "1\n#error"}}), GlError);
}

TEST_F(ShaderLibraryTest, CompileErrorNamesFileAndLine) {
  ShaderLibrary library;
  const std::string message = testing::thrownMessage<GlError>([&] { library.program({"tests/broken.frag"}); });
  const int line = lineOf("tests/broken.frag", "color.g = UNDECLARED");
  EXPECT_NE(message.find("shaders/tests/broken.frag:" + std::to_string(line) + ":"),
            std::string::npos)
      << "expected line " << line << " in:\n"
      << message;
  EXPECT_NE(message.find("UNDECLARED_IN_BROKEN_FRAG"), std::string::npos) << message;
  EXPECT_EQ(message.find("\n0:"), std::string::npos) << message;
  EXPECT_EQ(library.cachedPrograms(), 0u);
}

TEST_F(ShaderLibraryTest, CompileErrorInsideIncludeNamesTheIncludedFile) {
  ShaderLibrary library;
  const std::string message = testing::thrownMessage<GlError>([&] {
    library.program({"tests/triangle.vert", "tests/broken_include.frag"});
  });
  const int line = lineOf("tests/include_broken.glsl", "return UNDECLARED_IN_INCLUDE");
  EXPECT_NE(message.find("compiling shaders/tests/broken_include.frag"), std::string::npos)
      << message;
  // Both of Mesa's errors (the undeclared name and the bad return) are inside the include;
  // nothing may be blamed on the #include line of the including file.
  const std::string at = "shaders/tests/include_broken.glsl:" + std::to_string(line) + ":";
  const std::size_t first = message.find(at);
  EXPECT_NE(first, std::string::npos) << "expected line " << line << " in:\n" << message;
  EXPECT_NE(message.find("UNDECLARED_IN_INCLUDE"), std::string::npos) << message;
  EXPECT_LT(first, message.find("UNDECLARED_IN_INCLUDE")) << message;
  EXPECT_EQ(message.find("broken_include.frag:"), std::string::npos) << message;
}

TEST_F(ShaderLibraryTest, LinkErrorNamesTheFiles) {
  ShaderLibrary library;
  const std::string message = testing::thrownMessage<GlError>([&] {
    library.program({"tests/triangle.vert", "tests/link_mismatch.frag"});
  });
  EXPECT_NE(message.find("linking shaders/tests/triangle.vert + shaders/tests/link_mismatch.frag"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("vNotWritten"), std::string::npos) << message;
}

TEST_F(ShaderLibraryTest, ProgramsAreCachedByFilesAndDefines) {
  ShaderLibrary library;
  const Program& a = library.program({"tests/fill.comp"}, {{"OFFSET", "1"}});
  const Program& b = library.program({"tests/fill.comp"}, {{"OFFSET", "1"}});
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(library.cachedPrograms(), 1u);
  const Program& c = library.program({"tests/fill.comp"}, {{"OFFSET", "2"}});
  EXPECT_NE(a.id(), c.id());
  EXPECT_EQ(library.cachedPrograms(), 2u);
  const Program& d = library.program({"tests/triangle.vert", "tests/triangle.frag"});
  EXPECT_EQ(d.label(), "shaders/tests/triangle.vert + shaders/tests/triangle.frag");
  EXPECT_EQ(c.label(), "shaders/tests/fill.comp [OFFSET=2]");
  char buf[256] = {};
  GLsizei n = 0;
  glGetObjectLabel(GL_PROGRAM, c.id(), sizeof buf, &n, buf);
  EXPECT_EQ(std::string(buf, static_cast<std::size_t>(n)), c.label());
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(ShaderLibraryTest, RejectsBadStageSets) {
  ShaderLibrary library;
  EXPECT_THROW(library.program({}), GlError);
  EXPECT_THROW(library.program({"common/constants.glsl"}), GlError);
  EXPECT_THROW(library.program({"tests/fill.comp", "tests/triangle.frag"}), GlError);
  EXPECT_THROW(library.program({"tests/triangle.frag", "tests/link_mismatch.frag"}), GlError);
}

}  // namespace
}  // namespace radiant::gl
