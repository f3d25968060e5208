#pragma once
// Shaders are files under shaders/ embedded into the binary at build time (cmake/Embed.cmake,
// namespace radiant::shaders). The library prepends "#version 450 core" and the given #defines,
// resolves #include "common/..." recursively (with #line directives so errors map to the right file),
// and caches linked programs by (stage files, defines).
//
// When compilation fails it throws gl::GlError whose message names the shader file and the line,
// e.g. "shaders/direct/direct.frag:42: error C1008: undefined variable \"foo\"".

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/gl/Gl.h"

namespace radiant::gl {

using Defines = std::vector<std::pair<std::string, std::string>>;  // {"SAMPLES", "16"}

class ShaderLibrary {
public:
  // Source of an embedded file by its name relative to shaders/ ("common/brdf.glsl"); throws if absent.
  static std::string_view source(std::string_view name);
  // Preprocessed source (version, defines, includes expanded with #line). Exposed for tests.
  static std::string preprocess(std::string_view name, const Defines& defines);

  // Builds (or returns the cached) program. Stages are picked from the file extensions:
  // .vert .geom .frag .comp. The returned reference stays valid for the library's lifetime.
  const Program& program(const std::vector<std::string>& files, const Defines& defines = {});
  std::size_t cachedPrograms() const { return programs_.size(); }
  // Every program linked so far, keyed by its stage files and defines: what a frame's techniques use
  // (tests check their sampler units against each other without a list of them).
  const std::map<std::string, Program>& programs() const { return programs_; }

private:
  std::map<std::string, Program> programs_;
};

}  // namespace radiant::gl
