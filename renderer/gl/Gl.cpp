#include "renderer/gl/Gl.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace radiant::gl {

const char* errorName(GLenum error) {
  switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
    default: return "unknown GL error";
  }
}

void checkError(const char* where) {
  // GL keeps one flag per error kind and glGetError clears one per call (GL 4.5 core
  // section 2.3.1), so drain them all; otherwise a stale flag would be blamed on the next caller.
  // The cap guards against implementations that keep reporting GL_CONTEXT_LOST.
  std::string errors;
  for (int i = 0; i < 16; ++i) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    if (!errors.empty()) errors += ", ";
    errors += errorName(e);
    if (e == GL_CONTEXT_LOST) break;
  }
  if (!errors.empty()) throw GlError(std::string(where) + ": " + errors);
}

namespace {

// KHR_debug labels are what captures (RenderDoc, apitrace) and debug messages show. Labels longer
// than GL_MAX_LABEL_LENGTH are an error (GL 4.5 core section 20.9), so clip them.
void label(GLenum identifier, GLuint id, std::string_view text) {
  if (text.empty()) return;
  GLint maxLength = 256;  // the minimum the spec guarantees
  glGetIntegerv(GL_MAX_LABEL_LENGTH, &maxLength);
  const auto n = static_cast<GLsizei>(
      std::min<std::size_t>(text.size(), static_cast<std::size_t>(maxLength - 1)));
  glObjectLabel(identifier, id, n, text.data());
}

// A constructor that throws never runs its destructor, so a constructor that fails after
// glCreate* must delete the object itself before the exception leaves.
template <class Delete>
void checkCreated(const std::string& what, GLuint& id, Delete del) {
  try {
    checkError(what.c_str());
  } catch (...) {
    del(id);
    id = 0;
    throw;
  }
}

std::string where(const char* what, std::string_view labelText) {
  return std::string(what) + "(\"" + std::string(labelText) + "\")";
}

const char* framebufferStatusName(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_COMPLETE: return "GL_FRAMEBUFFER_COMPLETE";
    case GL_FRAMEBUFFER_UNDEFINED: return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS: return "GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS";
    case 0: return "0 (glCheckNamedFramebufferStatus failed)";
    default: return "unknown framebuffer status";
  }
}

// Integer textures are incomplete under linear filtering (GL 4.5 core section 8.17), so their
// default filter must be GL_NEAREST.
bool isIntegerFormat(GLenum internalFormat) {
  switch (internalFormat) {
    case GL_R8I:
    case GL_R8UI:
    case GL_R16I:
    case GL_R16UI:
    case GL_R32I:
    case GL_R32UI:
    case GL_RG8I:
    case GL_RG8UI:
    case GL_RG16I:
    case GL_RG16UI:
    case GL_RG32I:
    case GL_RG32UI:
    case GL_RGB8I:
    case GL_RGB8UI:
    case GL_RGB16I:
    case GL_RGB16UI:
    case GL_RGB32I:
    case GL_RGB32UI:
    case GL_RGBA8I:
    case GL_RGBA8UI:
    case GL_RGBA16I:
    case GL_RGBA16UI:
    case GL_RGBA32I:
    case GL_RGBA32UI:
    case GL_RGB10_A2UI: return true;
    default: return false;
  }
}

// Host arrays handed to upload()/download() are tightly packed; GL's default row alignment of 4
// would skew rows of e.g. RGB8 images with odd widths. Pixel-store state is per context and shared
// with other code, so it is set on every call rather than assumed.
void tightUnpack() { glPixelStorei(GL_UNPACK_ALIGNMENT, 1); }
void tightPack() { glPixelStorei(GL_PACK_ALIGNMENT, 1); }

}  // namespace

// --- Buffer ------------------------------------------------------------------------------------

Buffer::Buffer(std::string_view labelText, std::size_t bytes, const void* data, GLbitfield flags)
    : size_(bytes) {
  const std::string w = where("Buffer", labelText);
  // Zero-sized immutable storage is GL_INVALID_VALUE (GL 4.5 core section 6.2).
  if (bytes == 0) throw std::invalid_argument(w + ": size must be > 0");
  glCreateBuffers(1, &id_);
  label(GL_BUFFER, id_, labelText);
  glNamedBufferStorage(id_, static_cast<GLsizeiptr>(bytes), data, flags);
  // GL_OUT_OF_MEMORY surfaces here, at allocation.
  checkCreated(w, id_, [](GLuint id) { glDeleteBuffers(1, &id); });
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteBuffers(1, &id_);
    id_ = std::exchange(o.id_, 0);
    size_ = std::exchange(o.size_, 0);
  }
  return *this;
}

Buffer::~Buffer() {
  if (id_) glDeleteBuffers(1, &id_);
}

void Buffer::upload(const void* data, std::size_t bytes, std::size_t offset) {
  if (offset > size_ || bytes > size_ - offset)
    throw std::out_of_range("Buffer::upload: offset " + std::to_string(offset) + " + bytes " +
                            std::to_string(bytes) + " > size " + std::to_string(size_));
  // Needs GL_DYNAMIC_STORAGE_BIT on the storage (GL 4.5 core section 6.2.1).
  glNamedBufferSubData(id_, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}

void Buffer::download(void* data, std::size_t bytes, std::size_t offset) const {
  if (offset > size_ || bytes > size_ - offset)
    throw std::out_of_range("Buffer::download: offset " + std::to_string(offset) + " + bytes " +
                            std::to_string(bytes) + " > size " + std::to_string(size_));
  glGetNamedBufferSubData(id_, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
  checkError("Buffer::download");
}

void Buffer::bindBase(GLenum target, GLuint index) const { glBindBufferBase(target, index, id_); }

// --- Texture -----------------------------------------------------------------------------------

std::size_t textureBytes(GLenum target, GLenum internalFormat, int width, int height, int depth, int levels) {
  std::size_t texel = 16;
  switch (internalFormat) {
    case GL_R8: texel = 1; break;
    case GL_R16F: case GL_RG8: case GL_DEPTH_COMPONENT16: texel = 2; break;
    case GL_RGBA8: case GL_SRGB8_ALPHA8: case GL_R32F: case GL_R32UI: case GL_R32I: case GL_RG16F:
    case GL_R11F_G11F_B10F: case GL_RGB10_A2: case GL_DEPTH_COMPONENT24: case GL_DEPTH_COMPONENT32F:
    case GL_DEPTH24_STENCIL8: texel = 4; break;
    case GL_RGBA16F: case GL_RG32F: case GL_RG32UI: texel = 8; break;
    case GL_RGB32F: texel = 12; break;
    default: texel = 16; break;
  }
  const std::size_t faces = target == GL_TEXTURE_CUBE_MAP ? 6 : 1;
  const bool layered = target != GL_TEXTURE_3D;  // arrays keep their layers at every level
  std::size_t total = 0;
  int w = std::max(width, 0), h = std::max(height, 0), d = std::max(depth, 0);
  for (int level = 0; level < levels; ++level) {
    total += std::size_t(w) * std::size_t(h) * std::size_t(d) * faces * texel;
    w = std::max(1, w / 2);
    h = std::max(1, h / 2);
    if (!layered) d = std::max(1, d / 2);
  }
  return total;
}

Texture::Texture(std::string_view labelText, GLenum target, GLenum internalFormat, int width,
                 int height, int depth, int levels)
    : target_(target),
      format_(internalFormat),
      width_(width),
      height_(height),
      depth_(depth),
      levels_(levels) {
  const std::string w = where("Texture", labelText);
  if (width <= 0 || height <= 0 || depth <= 0 || levels <= 0)
    throw std::invalid_argument(w + ": size " + std::to_string(width) + "x" +
                                std::to_string(height) + "x" + std::to_string(depth) + ", " +
                                std::to_string(levels) + " levels: all must be > 0");
  if (target == GL_TEXTURE_CUBE_MAP_ARRAY && depth % 6 != 0)
    throw std::invalid_argument(w + ": cube map array depth " + std::to_string(depth) +
                                " is not a multiple of 6");
  glCreateTextures(target, 1, &id_);
  label(GL_TEXTURE, id_, labelText);
  switch (target) {
    case GL_TEXTURE_2D:
    case GL_TEXTURE_CUBE_MAP:  // six faces of width x height, allocated at once
      glTextureStorage2D(id_, levels, internalFormat, width, height);
      break;
    case GL_TEXTURE_2D_ARRAY:
    case GL_TEXTURE_CUBE_MAP_ARRAY:  // depth counts layer-faces (GL 4.5 core section 8.19)
    case GL_TEXTURE_3D:
      glTextureStorage3D(id_, levels, internalFormat, width, height, depth);
      break;
    default:
      glDeleteTextures(1, &id_);
      id_ = 0;
      throw std::invalid_argument(w + ": unsupported target 0x" + [&] {
        char buf[16];
        std::snprintf(buf, sizeof buf, "%04X", target);
        return std::string(buf);
      }());
  }
  // GL's default minification filter (GL_NEAREST_MIPMAP_LINEAR) makes a single-level texture
  // incomplete, and an incomplete texture samples as black without any error (GL 4.5 core
  // section 8.17). Pick filters that make every texture complete from the start.
  const bool integer = isIntegerFormat(internalFormat);
  const GLint minFilter = integer ? (levels > 1 ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST)
                                  : (levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTextureParameteri(id_, GL_TEXTURE_MIN_FILTER, minFilter);
  glTextureParameteri(id_, GL_TEXTURE_MAG_FILTER, integer ? GL_NEAREST : GL_LINEAR);
  checkCreated(w, id_, [](GLuint id) { glDeleteTextures(1, &id); });
}

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteTextures(1, &id_);
    id_ = std::exchange(o.id_, 0);
    target_ = std::exchange(o.target_, 0);
    format_ = std::exchange(o.format_, 0);
    width_ = std::exchange(o.width_, 0);
    height_ = std::exchange(o.height_, 0);
    depth_ = std::exchange(o.depth_, 0);
    levels_ = std::exchange(o.levels_, 0);
  }
  return *this;
}

Texture::~Texture() {
  if (id_) glDeleteTextures(1, &id_);
}

void Texture::setFilter(GLenum minFilter, GLenum magFilter) {
  glTextureParameteri(id_, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(minFilter));
  glTextureParameteri(id_, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(magFilter));
}

void Texture::setWrap(GLenum wrap) {
  glTextureParameteri(id_, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap));
  glTextureParameteri(id_, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap));
  glTextureParameteri(id_, GL_TEXTURE_WRAP_R, static_cast<GLint>(wrap));
}

void Texture::setWrap(GLenum wrapS, GLenum wrapT) {
  glTextureParameteri(id_, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrapS));
  glTextureParameteri(id_, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrapT));
}

void Texture::setCompare(GLenum func) {
  glTextureParameteri(id_, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(id_, GL_TEXTURE_COMPARE_FUNC, static_cast<GLint>(func));
}

void Texture::upload(int level, int x, int y, int z, int w, int h, int d, GLenum format,
                     GLenum type, const void* pixels) {
  tightUnpack();
  if (target_ == GL_TEXTURE_2D) {
    glTextureSubImage2D(id_, level, x, y, w, h, format, type, pixels);
  } else {
    // With DSA, cube maps are addressed as six layers: z is the face (GL 4.5 core section 8.6,
    // TextureSubImage3D), the same as cube map arrays' layer-faces.
    glTextureSubImage3D(id_, level, x, y, z, w, h, d, format, type, pixels);
  }
  checkError("Texture::upload");
}

void Texture::generateMipmaps() { glGenerateTextureMipmap(id_); }

void Texture::bindUnit(GLuint unit) const { glBindTextureUnit(unit, id_); }

void Texture::bindImage(GLuint unit, GLenum access, int level, bool layered, int layer) const {
  glBindImageTexture(unit, id_, level, layered ? GL_TRUE : GL_FALSE, layer, access, format_);
}

void Texture::download(int level, GLenum format, GLenum type, void* out, std::size_t bytes) const {
  tightPack();
  // The bufSize argument makes GL refuse (GL_INVALID_OPERATION) instead of overrunning `out`.
  glGetTextureImage(id_, level, format, type, static_cast<GLsizei>(bytes), out);
  checkError("Texture::download");
}

// --- Framebuffer -------------------------------------------------------------------------------

Framebuffer::Framebuffer(std::string_view labelText) {
  glCreateFramebuffers(1, &id_);
  label(GL_FRAMEBUFFER, id_, labelText);
  checkCreated(where("Framebuffer", labelText), id_,
               [](GLuint id) { glDeleteFramebuffers(1, &id); });
}

Framebuffer& Framebuffer::operator=(Framebuffer&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteFramebuffers(1, &id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

Framebuffer::~Framebuffer() {
  if (id_) glDeleteFramebuffers(1, &id_);
}

void Framebuffer::attach(GLenum attachment, const Texture& texture, int level, int layer) {
  if (layer < 0)
    glNamedFramebufferTexture(id_, attachment, texture.id(), level);
  else
    glNamedFramebufferTextureLayer(id_, attachment, texture.id(), level, layer);
  checkError("Framebuffer::attach");
}

void Framebuffer::setDrawBuffers(std::initializer_list<GLenum> buffers) {
  glNamedFramebufferDrawBuffers(id_, static_cast<GLsizei>(buffers.size()), buffers.begin());
  checkError("Framebuffer::setDrawBuffers");
}

void Framebuffer::checkComplete(const char* whereText) const {
  const GLenum status = glCheckNamedFramebufferStatus(id_, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw GlError(std::string(whereText) +
                  ": framebuffer incomplete: " + framebufferStatusName(status));
}

void Framebuffer::bind() const { glBindFramebuffer(GL_FRAMEBUFFER, id_); }

// --- VertexArray -------------------------------------------------------------------------------

VertexArray::VertexArray(std::string_view labelText) {
  glCreateVertexArrays(1, &id_);
  label(GL_VERTEX_ARRAY, id_, labelText);
  checkCreated(where("VertexArray", labelText), id_,
               [](GLuint id) { glDeleteVertexArrays(1, &id); });
}

VertexArray& VertexArray::operator=(VertexArray&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteVertexArrays(1, &id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

VertexArray::~VertexArray() {
  if (id_) glDeleteVertexArrays(1, &id_);
}

void VertexArray::attribute(GLuint attrib, GLuint binding, const Buffer& buffer, int components,
                            GLsizei stride, GLintptr offset) {
  // Separate attribute format (GL 4.5 core section 10.3.1): the buffer binding carries the
  // offset and stride, the attribute only its type, so attributes can share one binding.
  glVertexArrayVertexBuffer(id_, binding, buffer.id(), offset, stride);
  glEnableVertexArrayAttrib(id_, attrib);
  glVertexArrayAttribFormat(id_, attrib, components, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(id_, attrib, binding);
  checkError("VertexArray::attribute");
}

void VertexArray::elements(const Buffer& indexBuffer) {
  glVertexArrayElementBuffer(id_, indexBuffer.id());
}

void VertexArray::bind() const { glBindVertexArray(id_); }

// --- Program -----------------------------------------------------------------------------------

Program& Program::operator=(Program&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(o.id_, 0);
    label_ = std::move(o.label_);
    o.label_.clear();
  }
  return *this;
}

Program::~Program() {
  if (id_) glDeleteProgram(id_);
}

void Program::use() const { glUseProgram(id_); }

GLint Program::uniformLocation(const char* name) const { return glGetUniformLocation(id_, name); }

void Program::set(const char* name, int v) const {
  const GLint loc = uniformLocation(name);
  if (loc >= 0) glProgramUniform1i(id_, loc, v);
}

void Program::set(const char* name, float v) const {
  const GLint loc = uniformLocation(name);
  if (loc >= 0) glProgramUniform1f(id_, loc, v);
}

void Program::set(const char* name, const float* vec, int components) const {
  const GLint loc = uniformLocation(name);
  if (loc < 0) return;
  switch (components) {
    case 1: glProgramUniform1fv(id_, loc, 1, vec); break;
    case 2: glProgramUniform2fv(id_, loc, 1, vec); break;
    case 3: glProgramUniform3fv(id_, loc, 1, vec); break;
    case 4: glProgramUniform4fv(id_, loc, 1, vec); break;
    default:
      throw std::invalid_argument("Program::set(\"" + std::string(name) + "\"): components " +
                                  std::to_string(components) + " not in 1..4");
  }
}

void Program::setMat4(const char* name, const float* m) const {
  const GLint loc = uniformLocation(name);
  if (loc >= 0) glProgramUniformMatrix4fv(id_, loc, 1, GL_FALSE, m);  // column-major, like glm
}

// --- TimerQuery --------------------------------------------------------------------------------

TimerQuery::TimerQuery(std::string_view labelText) {
  // glCreateQueries, unlike glGenQueries, creates the object now, so it can be labelled before its
  // first glBeginQuery (GL 4.5 core section 4.2).
  glCreateQueries(GL_TIME_ELAPSED, 1, &id_);
  label(GL_QUERY, id_, labelText);
  checkCreated(where("TimerQuery", labelText), id_, [](GLuint id) { glDeleteQueries(1, &id); });
}

TimerQuery& TimerQuery::operator=(TimerQuery&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteQueries(1, &id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

TimerQuery::~TimerQuery() {
  if (id_) glDeleteQueries(1, &id_);
}

// Only one GL_TIME_ELAPSED query may be active at a time (GL 4.5 core section 4.3): nesting is
// GL_INVALID_OPERATION, so the profiler times passes one after another.
void TimerQuery::begin() { glBeginQuery(GL_TIME_ELAPSED, id_); }

void TimerQuery::end() { glEndQuery(GL_TIME_ELAPSED); }

bool TimerQuery::resultAvailable() const {
  GLuint available = GL_FALSE;
  glGetQueryObjectuiv(id_, GL_QUERY_RESULT_AVAILABLE, &available);
  return available != GL_FALSE;
}

std::uint64_t TimerQuery::resultNs() const {
  // 64-bit: a 32-bit result wraps after 4.3 s of GPU time.
  GLuint64 ns = 0;
  glGetQueryObjectui64v(id_, GL_QUERY_RESULT, &ns);
  checkError("TimerQuery::resultNs");
  return ns;
}

// --- DebugGroup --------------------------------------------------------------------------------

DebugGroup::DebugGroup(std::string_view name) {
  GLint maxLength = 256;
  glGetIntegerv(GL_MAX_DEBUG_MESSAGE_LENGTH, &maxLength);
  const auto n = static_cast<GLsizei>(
      std::min<std::size_t>(name.size(), static_cast<std::size_t>(maxLength - 1)));
  glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, n, name.data());
}

DebugGroup::~DebugGroup() { glPopDebugGroup(); }

}  // namespace radiant::gl
