#pragma once
// Move-only RAII wrappers over OpenGL 4.5 objects, created with DSA (glCreate*), each with a KHR_debug
// label. Technique code never holds a raw GLuint: it holds these.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <epoxy/gl.h>

namespace radiant::gl {

// An environment failure from GL: the message names the call and decodes the error.
struct GlError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "GL_INVALID_OPERATION" etc.
const char* errorName(GLenum error);
// Throws GlError("<where>: GL_INVALID_ENUM") if glGetError() reports an error (drains all of them).
void checkError(const char* where);

// Base for move-only handles. Deleter is a function pointer taking the name.
class Object {
public:
  Object() = default;
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;
  Object(Object&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
protected:
  explicit Object(GLuint id) : id_(id) {}
  GLuint id_ = 0;
};

class Buffer : public Object {
public:
  Buffer() = default;
  // Immutable storage (glNamedBufferStorage). flags e.g. GL_DYNAMIC_STORAGE_BIT.
  Buffer(std::string_view label, std::size_t bytes, const void* data = nullptr,
         GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
  Buffer(Buffer&&) noexcept = default;
  Buffer& operator=(Buffer&& o) noexcept;
  ~Buffer();
  std::size_t size() const { return size_; }
  void upload(const void* data, std::size_t bytes, std::size_t offset = 0);
  void download(void* data, std::size_t bytes, std::size_t offset = 0) const;
  void bindBase(GLenum target, GLuint index) const;  // GL_UNIFORM_BUFFER / GL_SHADER_STORAGE_BUFFER
private:
  std::size_t size_ = 0;
};

class Texture : public Object {
public:
  Texture() = default;
  // target: GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_2D_ARRAY, GL_TEXTURE_CUBE_MAP_ARRAY.
  // depth = layers for arrays (for cube map arrays: number of layer-faces, a multiple of 6).
  Texture(std::string_view label, GLenum target, GLenum internalFormat, int width, int height,
          int depth = 1, int levels = 1);
  Texture(Texture&&) noexcept = default;
  Texture& operator=(Texture&& o) noexcept;
  ~Texture();
  GLenum target() const { return target_; }
  GLenum format() const { return format_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int depth() const { return depth_; }
  int levels() const { return levels_; }
  void setFilter(GLenum minFilter, GLenum magFilter);
  void setWrap(GLenum wrap);
  void setWrap(GLenum wrapS, GLenum wrapT);  // 2-D: s and t apart (an equirect map wraps in u only)
  // Depth textures: enable hardware comparison (sampler2DShadow) with the given func.
  void setCompare(GLenum func);
  void upload(int level, int x, int y, int z, int w, int h, int d, GLenum format, GLenum type,
              const void* pixels);
  void generateMipmaps();
  void bindUnit(GLuint unit) const;  // glBindTextureUnit
  void bindImage(GLuint unit, GLenum access, int level = 0, bool layered = false, int layer = 0) const;
  // Reads a whole level (glGetTextureImage).
  void download(int level, GLenum format, GLenum type, void* out, std::size_t bytes) const;
private:
  GLenum target_ = 0, format_ = 0;
  int width_ = 0, height_ = 0, depth_ = 0, levels_ = 0;
};

// Bytes of a texture's storage, all levels and faces (its internal format's texel size; 16 bytes for a
// format this does not know, which over-counts rather than under-counts).
std::size_t textureBytes(GLenum target, GLenum internalFormat, int width, int height, int depth, int levels);
inline std::size_t textureBytes(const Texture& t) {
  return textureBytes(t.target(), t.format(), t.width(), t.height(), t.depth(), t.levels());
}

class Framebuffer : public Object {
public:
  Framebuffer() = default;
  explicit Framebuffer(std::string_view label);
  Framebuffer(Framebuffer&&) noexcept = default;
  Framebuffer& operator=(Framebuffer&& o) noexcept;
  ~Framebuffer();
  // attachment: GL_COLOR_ATTACHMENTi or GL_DEPTH_ATTACHMENT. layer < 0 attaches all layers (layered).
  void attach(GLenum attachment, const Texture& texture, int level = 0, int layer = -1);
  void setDrawBuffers(std::initializer_list<GLenum> buffers);
  // Throws GlError naming the status (GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT ...) unless complete.
  void checkComplete(const char* where) const;
  void bind() const;  // glBindFramebuffer(GL_FRAMEBUFFER, id)
};

class VertexArray : public Object {
public:
  VertexArray() = default;
  explicit VertexArray(std::string_view label);
  VertexArray(VertexArray&&) noexcept = default;
  VertexArray& operator=(VertexArray&& o) noexcept;
  ~VertexArray();
  // Binds `buffer` to binding `binding` and describes float attribute `attrib` with `components`.
  void attribute(GLuint attrib, GLuint binding, const Buffer& buffer, int components,
                 GLsizei stride, GLintptr offset = 0);
  void elements(const Buffer& indexBuffer);
  void bind() const;
};

class Program : public Object {
public:
  Program() = default;
  Program(GLuint id, std::string label) : Object(id), label_(std::move(label)) {}
  Program(Program&&) noexcept = default;
  Program& operator=(Program&& o) noexcept;
  ~Program();
  const std::string& label() const { return label_; }
  void use() const;
  GLint uniformLocation(const char* name) const;  // -1 when absent (optimised out)
  // glProgramUniform* helpers by name; silently ignore absent uniforms.
  void set(const char* name, int v) const;
  void set(const char* name, float v) const;
  void set(const char* name, const float* vec, int components) const;  // vec2/3/4
  void setMat4(const char* name, const float* m) const;
private:
  std::string label_;
};

// A GL_TIME_ELAPSED query with a 64-bit result, readable without stalling (resultAvailable()).
class TimerQuery : public Object {
public:
  TimerQuery() = default;
  explicit TimerQuery(std::string_view label);
  TimerQuery(TimerQuery&&) noexcept = default;
  TimerQuery& operator=(TimerQuery&& o) noexcept;
  ~TimerQuery();
  void begin();
  void end();
  bool resultAvailable() const;
  std::uint64_t resultNs() const;  // blocks if not yet available
};

// RAII scope for GL debug groups (KHR_debug push/pop), so captures and logs show pass names.
class DebugGroup {
public:
  explicit DebugGroup(std::string_view name);
  ~DebugGroup();
  DebugGroup(const DebugGroup&) = delete;
  DebugGroup& operator=(const DebugGroup&) = delete;
};

}  // namespace radiant::gl
