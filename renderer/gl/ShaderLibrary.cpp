#include "renderer/gl/ShaderLibrary.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <memory>
#include <optional>

#include "embedded/radiant_shaders.h"

namespace radiant::gl {

namespace {

// Errors name files the way a developer finds them in the tree: "shaders/<name>".
std::string display(std::string_view name) {
  if (!name.empty() && name.front() == '<') return std::string(name);  // "<defines>"
  return "shaders/" + std::string(name);
}

std::string_view trimLeft(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

std::string_view trim(std::string_view s) {
  s = trimLeft(s);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// For a preprocessor line ("  #  include ..."), the directive word ("include") and what follows.
// GLSL 4.50 section 3.3: '#' may be preceded and followed only by spaces and tabs.
std::optional<std::pair<std::string_view, std::string_view>> directive(std::string_view line) {
  line = trimLeft(line);
  if (line.empty() || line.front() != '#') return std::nullopt;
  line = trimLeft(line.substr(1));
  std::size_t n = 0;
  while (n < line.size() && (std::isalnum(static_cast<unsigned char>(line[n])) || line[n] == '_'))
    ++n;
  return std::make_pair(line.substr(0, n), line.substr(n));
}

bool isIdentifier(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s.front()))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

struct Preprocessed {
  std::string text;
  std::vector<std::string> files;  // GLSL source-string number -> embedded name
};

// Each file's lines are numbered from index * kLineStride + 1, so the line number alone names the
// file. The source-string number of "#line L S" should be enough, but Mesa 22 reports some errors
// (e.g. "undeclared identifier") with source string 0 and the right line, which would blame the
// main file for an error in an include. Decoding from the line works either way.
constexpr int kLineStride = 100000;

// Expands #include "name" by text substitution. Each file gets a source-string number, announced
// with "#line <line> <number>" at its start and after every include it makes, so the compiler's
// locations point into the original files. GLSL 4.50 section 3.3: after "#line L S" the next line
// is line L of source string S (GLSL >= 3.30; older versions used L+1).
class Preprocessor {
public:
  Preprocessed run(std::string_view name, const Defines& defines) {
    indexOf(name);  // the stage's own file is source string 0
    out_ = "#version 450 core\n";
    if (!defines.empty()) {
      const int index = indexOf("<defines>");
      out_ +=
          "#line " + std::to_string(index * kLineStride + 1) + " " + std::to_string(index) + "\n";
      for (const auto& [key, value] : defines) {
        if (!isIdentifier(key))
          throw GlError("ShaderLibrary: define name \"" + key + "\" is not an identifier");
        if (value.find_first_of("\r\n") != std::string::npos)
          throw GlError("ShaderLibrary: define " + key + " has a line break in its value");
        out_ += "#define " + key + (value.empty() ? "" : " " + value) + "\n";
      }
    }
    expand(name);
    return {std::move(out_), std::move(files_)};
  }

private:
  int indexOf(std::string_view name) {
    auto it = std::find(files_.begin(), files_.end(), name);
    if (it != files_.end()) return static_cast<int>(it - files_.begin());
    files_.emplace_back(name);
    return static_cast<int>(files_.size()) - 1;
  }

  void expand(std::string_view name) {
    const std::string_view src = ShaderLibrary::source(name);
    const int index = indexOf(name);
    stack_.emplace_back(name);
    const auto restore = [&](int nextLine) {
      out_ += "#line " + std::to_string(index * kLineStride + nextLine) + " " +
              std::to_string(index) + "\n";
    };
    restore(1);
    bool included = false;
    int lineNo = 0;
    std::size_t pos = 0;
    while (pos < src.size()) {
      std::size_t end = src.find('\n', pos);
      if (end == std::string_view::npos) end = src.size();
      std::string_view line = src.substr(pos, end - pos);
      pos = end + 1;
      ++lineNo;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      const std::string here = display(name) + ":" + std::to_string(lineNo);

      const auto d = directive(line);
      if (d && d->first == "include") {
        const std::string_view arg = trim(d->second);
        const std::size_t close = arg.size() >= 2 ? arg.find('"', 1) : std::string_view::npos;
        const std::string_view rest =
            close == std::string_view::npos ? std::string_view() : trim(arg.substr(close + 1));
        if (arg.empty() || arg.front() != '"' || close == std::string_view::npos ||
            !(rest.empty() || rest.substr(0, 2) == "//"))
          throw GlError(here + ": malformed #include (expected #include \"common/file.glsl\")");
        const std::string target(arg.substr(1, close - 1));
        if (std::find(stack_.begin(), stack_.end(), target) != stack_.end()) {
          std::string chain;
          for (const auto& s : stack_) chain += s + " -> ";
          throw GlError(here + ": #include cycle: " + chain + target);
        }
        if (radiant::shaders::find(target).data() == nullptr)
          throw GlError(here + ": #include \"" + target + "\": no such embedded shader");
        expand(target);
        restore(lineNo + 1);
        included = true;
        continue;
      }
      if (d && d->first == "version")
        throw GlError(here + ": #version is not allowed: the library prepends #version 450 core");
      out_ += line;
      out_ += '\n';
      // An #include inside a skipped #if group is skipped with its restoring #line, which would
      // leave the count off by the included length; re-announcing after each branch end fixes it.
      if (included && d && (d->first == "endif" || d->first == "else" || d->first == "elif"))
        restore(lineNo + 1);
    }
    stack_.pop_back();
  }

  std::string out_;
  std::vector<std::string> files_;
  std::vector<std::string> stack_;
};

bool parseInt(std::string_view s, int& v) {
  if (s.empty()) return false;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size();
}

// Rewrites the compiler's source-string locations into file names. Understands Mesa
// ("0:42(7): error: ..."), NVIDIA ("0(42) : error C1008: ...") and AMD ("ERROR: 0:42: ...").
std::string rewriteLog(std::string_view log, const std::vector<std::string>& files) {
  // Returns "shaders/<file>:<line>" for a reported (source string, line), or nothing if the
  // location is not one of ours. The source string is ignored: see kLineStride.
  const auto location = [&](int /*sourceString*/, int line) -> std::optional<std::string> {
    const int index = line / kLineStride;
    if (line <= 0 || index >= static_cast<int>(files.size())) return std::nullopt;
    return display(files[static_cast<std::size_t>(index)]) + ":" +
           std::to_string(line % kLineStride);
  };
  std::string out;
  std::size_t pos = 0;
  while (pos < log.size()) {
    std::size_t end = log.find('\n', pos);
    if (end == std::string_view::npos) end = log.size();
    std::string_view line = log.substr(pos, end - pos);
    pos = end + 1;
    std::string rewritten;
    int index = 0, lineNo = 0, column = 0;
    std::string_view prefix;
    std::string_view body = line;
    if (body.substr(0, 7) == "ERROR: " || body.substr(0, 9) == "WARNING: ") {
      prefix = body.substr(0, body.find(' ') + 1);
      body.remove_prefix(prefix.size());
    }
    const std::size_t colon = body.find(':');
    const std::size_t paren = body.find('(');
    if (colon != std::string_view::npos && parseInt(body.substr(0, colon), index)) {
      // Mesa "S:L(C): msg" or AMD "S:L: msg"
      std::string_view after = body.substr(colon + 1);
      const std::size_t open = after.find('(');
      const std::size_t sep = after.find(':');
      if (open != std::string_view::npos && open < sep && parseInt(after.substr(0, open), lineNo)) {
        const std::size_t close = after.find(')', open);
        if (close != std::string_view::npos &&
            parseInt(after.substr(open + 1, close - open - 1), column) &&
            after.substr(close + 1, 1) == ":") {
          if (auto at = location(index, lineNo))
            rewritten =
                *at + ":" + std::to_string(column) + ":" + std::string(after.substr(close + 2));
        }
      } else if (sep != std::string_view::npos && parseInt(after.substr(0, sep), lineNo)) {
        if (auto at = location(index, lineNo))
          rewritten = std::string(prefix) + *at + ":" + std::string(after.substr(sep + 1));
      }
    } else if (paren != std::string_view::npos && parseInt(body.substr(0, paren), index)) {
      // NVIDIA "S(L) : msg"
      const std::size_t close = body.find(')', paren);
      if (close != std::string_view::npos &&
          parseInt(body.substr(paren + 1, close - paren - 1), lineNo)) {
        std::string_view rest = trimLeft(body.substr(close + 1));
        if (!rest.empty() && rest.front() == ':') rest.remove_prefix(1);
        if (auto at = location(index, lineNo)) rewritten = *at + ":" + std::string(rest);
      }
    }
    if (rewritten.empty()) rewritten = std::string(line);
    if (!trim(rewritten).empty()) out += rewritten + "\n";
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

std::string describeDefines(const Defines& defines) {
  std::string s;
  for (const auto& [k, v] : defines) s += (s.empty() ? "" : ", ") + k + (v.empty() ? "" : "=" + v);
  return s;
}

GLenum stageOf(const std::string& file) {
  const auto dot = file.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : file.substr(dot);
  if (ext == ".vert") return GL_VERTEX_SHADER;
  if (ext == ".geom") return GL_GEOMETRY_SHADER;
  if (ext == ".frag") return GL_FRAGMENT_SHADER;
  if (ext == ".comp") return GL_COMPUTE_SHADER;
  throw GlError("ShaderLibrary: " + display(file) +
                ": unknown shader stage (expected .vert .geom .frag or .comp)");
}

// Owns a shader object until the program is linked; GL keeps attached shaders alive on its own
// only while attached.
struct ShaderObject {
  GLuint id = 0;
  explicit ShaderObject(GLenum stage) : id(glCreateShader(stage)) {}
  ShaderObject(const ShaderObject&) = delete;
  ShaderObject& operator=(const ShaderObject&) = delete;
  ~ShaderObject() {
    if (id) glDeleteShader(id);
  }
};

// Labels longer than GL_MAX_LABEL_LENGTH are GL_INVALID_VALUE (GL 4.5 core section 20.9), and a
// program of several files with defines can exceed the guaranteed 256.
void labelObject(GLenum identifier, GLuint id, const std::string& text) {
  GLint maxLength = 256;
  glGetIntegerv(GL_MAX_LABEL_LENGTH, &maxLength);
  const auto n = static_cast<GLsizei>(
      std::min<std::size_t>(text.size(), static_cast<std::size_t>(std::max(maxLength - 1, 0))));
  glObjectLabel(identifier, id, n, text.data());
}

std::string infoLog(GLuint object, bool program) {
  GLint length = 0;
  if (program)
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  else
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  GLsizei written = 0;
  if (program)
    glGetProgramInfoLog(object, length, &written, log.data());
  else
    glGetShaderInfoLog(object, length, &written, log.data());
  log.resize(static_cast<std::size_t>(std::max(written, 0)));
  return log;
}

}  // namespace

std::string_view ShaderLibrary::source(std::string_view name) {
  const std::string_view s = radiant::shaders::find(name);
  if (s.data() == nullptr)
    throw GlError("ShaderLibrary: no embedded shader \"" + std::string(name) + "\" (" +
                  std::to_string(radiant::shaders::names().size()) +
                  " embedded; names are relative to shaders/, e.g. \"common/constants.glsl\")");
  return s;
}

std::string ShaderLibrary::preprocess(std::string_view name, const Defines& defines) {
  return Preprocessor().run(name, defines).text;
}

const Program& ShaderLibrary::program(const std::vector<std::string>& files,
                                      const Defines& defines) {
  if (files.empty()) throw GlError("ShaderLibrary::program(): no shader files given");
  std::string key;
  // Newline-separated: neither file names nor define values may contain one (define values are
  // checked by the preprocessor), and define names cannot contain '=', so keys never collide.
  for (const auto& f : files) key += f + "\n";
  key += "\n";
  for (const auto& [k, v] : defines) key += k + "=" + v + "\n";
  if (auto it = programs_.find(key); it != programs_.end()) return it->second;

  std::string name;  // "shaders/a.vert + shaders/b.frag [A=1]"
  for (const auto& f : files) name += (name.empty() ? "" : " + ") + display(f);
  const std::string defs = describeDefines(defines);
  const std::string label = defs.empty() ? name : name + " [" + defs + "]";

  std::vector<GLenum> stages;
  for (const auto& f : files) {
    const GLenum stage = stageOf(f);
    if (std::find(stages.begin(), stages.end(), stage) != stages.end())
      throw GlError("ShaderLibrary: " + label + ": two files for the stage of " + display(f));
    stages.push_back(stage);
  }
  const bool compute = std::find(stages.begin(), stages.end(), GL_COMPUTE_SHADER) != stages.end();
  if (compute && stages.size() > 1)
    throw GlError("ShaderLibrary: " + label + ": a compute shader cannot be linked with others");

  Program program(glCreateProgram(), label);
  if (!program) throw GlError("ShaderLibrary: glCreateProgram failed for " + label);
  labelObject(GL_PROGRAM, program.id(), label);

  std::vector<std::unique_ptr<ShaderObject>> shaders;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Preprocessed pre = Preprocessor().run(files[i], defines);
    auto shader = std::make_unique<ShaderObject>(stages[i]);
    labelObject(GL_SHADER, shader->id, display(files[i]));
    const char* text = pre.text.c_str();
    const auto length = static_cast<GLint>(pre.text.size());
    glShaderSource(shader->id, 1, &text, &length);
    glCompileShader(shader->id);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader->id, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      throw GlError("ShaderLibrary: compiling " + display(files[i]) +
                    (defs.empty() ? "" : " [" + defs + "]") + " failed:\n" +
                    rewriteLog(infoLog(shader->id, false), pre.files));
    }
    glAttachShader(program.id(), shader->id);
    shaders.push_back(std::move(shader));
  }
  glLinkProgram(program.id());
  GLint linked = GL_FALSE;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &linked);
  // Detached shaders are deleted with their ShaderObject; the linked program does not need them.
  for (const auto& s : shaders) glDetachShader(program.id(), s->id);
  if (!linked)
    throw GlError("ShaderLibrary: linking " + label + " failed:\n" +
                  std::string(trim(infoLog(program.id(), true))));
  checkError(("ShaderLibrary: building " + label).c_str());
  return programs_.emplace(std::move(key), std::move(program)).first->second;
}

}  // namespace radiant::gl
