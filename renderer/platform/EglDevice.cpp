#include "renderer/platform/EglDevice.h"

// libepoxy resolves every EGL and GL entry point (extensions included) on first use, so the EGL
// headers must come from epoxy and never from <EGL/egl.h>.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string_view>
#include <utility>
#include <vector>

namespace radiant {

#ifdef RADIANT_GL_DEBUG_DEFAULT
constexpr bool kDebugByDefault = true;  // Debug builds: see renderer/platform/CMakeLists.txt
#else
constexpr bool kDebugByDefault = false;
#endif

const char* eglErrorName(int error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    case EGL_BAD_DEVICE_EXT: return "EGL_BAD_DEVICE_EXT";
    default: return "unknown EGL error";
  }
}

namespace {

constexpr const char* kCreate = "EglDevice::create()";

// eglGetError() must be read right after the failing call: every EGL call, successful or not,
// overwrites the thread's error (EGL 1.5 section 3.1).
std::string failed(const char* call) {
  return std::string(call) + " failed: " + eglErrorName(eglGetError());
}

// Extension strings are space-separated tokens; a plain substring search would let
// "EGL_KHR_surfaceless_context_foo" satisfy "EGL_KHR_surfaceless_context".
bool hasToken(const char* list, std::string_view token) {
  if (list == nullptr) return false;
  std::string_view s(list);
  std::size_t pos = 0;
  while (pos < s.size()) {
    std::size_t end = s.find(' ', pos);
    if (end == std::string_view::npos) end = s.size();
    if (s.substr(pos, end - pos) == token) return true;
    pos = end + 1;
  }
  return false;
}

std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(), [](unsigned char c) { return std::tolower(c); });
  return r;
}

bool containsIgnoreCase(std::string_view haystack, std::string_view needle) {
  return lower(haystack).find(lower(needle)) != std::string::npos;
}

std::string glString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "";
}

// EGL hands out one EGLDisplay per (platform, device) for the whole process, and eglTerminate
// invalidates it for everyone (EGL 1.5 section 3.2). Without EGL_KHR_display_reference (Mesa 22
// lacks it) two EglDevice instances on the same device would pull the display from under each
// other, so initialisation is reference-counted here.
std::mutex gDisplayMutex;
std::map<EGLDisplay, int> gDisplayRefs;

void acquireDisplay(EGLDisplay display) {
  std::lock_guard lock(gDisplayMutex);
  EGLint major = 0, minor = 0;
  // Harmless on an initialised display; keeps the refcount honest if someone else terminated it.
  if (!eglInitialize(display, &major, &minor)) throw EglError(failed("eglInitialize"));
  ++gDisplayRefs[display];
}

void releaseDisplay(EGLDisplay display) {
  std::lock_guard lock(gDisplayMutex);
  auto it = gDisplayRefs.find(display);
  if (it == gDisplayRefs.end()) return;
  if (--it->second == 0) {
    gDisplayRefs.erase(it);
    eglTerminate(display);
  }
}

const char* debugSourceName(GLenum source) {
  switch (source) {
    case GL_DEBUG_SOURCE_API: return "api";
    case GL_DEBUG_SOURCE_WINDOW_SYSTEM: return "window-system";
    case GL_DEBUG_SOURCE_SHADER_COMPILER: return "shader-compiler";
    case GL_DEBUG_SOURCE_THIRD_PARTY: return "third-party";
    case GL_DEBUG_SOURCE_APPLICATION: return "application";
    default: return "other";
  }
}

const char* debugTypeName(GLenum type) {
  switch (type) {
    case GL_DEBUG_TYPE_ERROR: return "error";
    case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR: return "deprecated";
    case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR: return "undefined-behavior";
    case GL_DEBUG_TYPE_PORTABILITY: return "portability";
    case GL_DEBUG_TYPE_PERFORMANCE: return "performance";
    case GL_DEBUG_TYPE_MARKER: return "marker";
    case GL_DEBUG_TYPE_PUSH_GROUP: return "push-group";
    case GL_DEBUG_TYPE_POP_GROUP: return "pop-group";
    default: return "other";
  }
}

const char* debugSeverityName(GLenum severity) {
  switch (severity) {
    case GL_DEBUG_SEVERITY_HIGH: return "high";
    case GL_DEBUG_SEVERITY_MEDIUM: return "medium";
    case GL_DEBUG_SEVERITY_LOW: return "low";
    default: return "notification";
  }
}

void GLAPIENTRY logDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity,
                                GLsizei length, const GLchar* message, const void*) {
  // length < 0 means NUL-terminated (KHR_debug).
  const int n = length < 0 ? static_cast<int>(std::string_view(message).size()) : length;
  std::fprintf(stderr, "[gl %s %s %s #%u] %.*s\n", debugSeverityName(severity),
               debugSourceName(source), debugTypeName(type), id, n, message);
}

bool debugRequestedByEnvironment() {
  const char* v = std::getenv("RADIANT_GL_DEBUG");
  return v != nullptr && *v != '\0' && std::string_view(v) != "0";
}

// Mesa 22 llvmpipe bins a GL_TIME_ELAPSED begin only into the tiles of the framebuffer its setup
// module already knows. Before the context's first draw or clear it knows none, so the first query
// loses its start time and reports the absolute CLOCK_MONOTONIC time (minutes) as its duration.
// One clear of a 1x1 framebuffer primes the setup module; later framebuffers of any size are fine
// (checked in tests/gl/gl/GlTest.cpp, TimerQueryMeasuresDraw).
void warmUpLlvmpipe() {
  GLuint texture = 0, framebuffer = 0;
  GLint previous = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &previous);
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA8, 1, 1);
  glCreateFramebuffers(1, &framebuffer);
  glNamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0, texture, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glClear(GL_COLOR_BUFFER_BIT);
  glFinish();
  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(previous));
  glDeleteFramebuffers(1, &framebuffer);
  glDeleteTextures(1, &texture);
}

// One way to reach a display: an enumerated EGL device, or Mesa's surfaceless platform.
struct Candidate {
  EGLenum platform = EGL_PLATFORM_DEVICE_EXT;
  EGLDeviceEXT device = EGL_NO_DEVICE_EXT;
  int index = -1;
  std::string extensions;
  bool software = false;

  std::string label() const {
    if (platform == EGL_PLATFORM_SURFACELESS_MESA) return "surfaceless platform";
    return "device " + std::to_string(index) + (software ? " (software)" : " (hardware)");
  }
};

}  // namespace

struct EglDevice::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;  // a 1x1 pbuffer only without EGL_KHR_surfaceless_context
  bool displayAcquired = false;
  bool resetStatusAvailable = false;
  bool loseContextOnReset = false;  // without it glGetGraphicsResetStatus always says GL_NO_ERROR

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  ~Impl() {
    if (context != EGL_NO_CONTEXT) {
      // A context current on another thread is only flagged for deletion by eglDestroyContext and
      // freed when that thread releases it (EGL 1.5 section 3.7.2); here we can release our own.
      if (eglGetCurrentContext() == context)
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
    }
    if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
    if (displayAcquired) releaseDisplay(display);
  }

  // Opens a display for the candidate and makes a 4.5 core context current. Throws EglError with
  // the failing call (no "EglDevice::create()" prefix: the caller adds it with the candidate).
  static std::unique_ptr<Impl> open(const Candidate& c, bool debug);
};

std::unique_ptr<EglDevice::Impl> EglDevice::Impl::open(const Candidate& c, bool debug) {
  auto impl = std::make_unique<Impl>();
  void* native = c.platform == EGL_PLATFORM_DEVICE_EXT ? static_cast<void*>(c.device)
                                                       : static_cast<void*>(EGL_DEFAULT_DISPLAY);
  impl->display = eglGetPlatformDisplayEXT(c.platform, native, nullptr);
  if (impl->display == EGL_NO_DISPLAY) throw EglError(failed("eglGetPlatformDisplayEXT"));
  acquireDisplay(impl->display);
  impl->displayAcquired = true;
  EGLDisplay dpy = impl->display;

  const int eglVersion = epoxy_egl_version(dpy);  // 15 for EGL 1.5
  const char* ext = eglQueryString(dpy, EGL_EXTENSIONS);
  const bool khrCreateContext = hasToken(ext, "EGL_KHR_create_context");
  if (eglVersion < 15 && !khrCreateContext)
    throw EglError("EGL " + std::to_string(eglVersion / 10) + "." +
                   std::to_string(eglVersion % 10) +
                   " without EGL_KHR_create_context cannot request an OpenGL 4.5 core context");
  const bool surfaceless = hasToken(ext, "EGL_KHR_surfaceless_context");
  const bool noConfig = surfaceless && (hasToken(ext, "EGL_KHR_no_config_context") ||
                                        hasToken(ext, "EGL_MESA_configless_context"));
  const bool robustnessExt = hasToken(ext, "EGL_EXT_create_context_robustness");

  if (!eglBindAPI(EGL_OPENGL_API)) throw EglError(failed("eglBindAPI(EGL_OPENGL_API)"));

  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!noConfig) {
    // EGL_SURFACE_TYPE defaults to EGL_WINDOW_BIT in eglChooseConfig; a headless display may have
    // no window configs at all, so ask for pbuffer configs (or any, when we need no surface).
    // clang-format off
    const EGLint configAttribs[] = {
        EGL_SURFACE_TYPE, surfaceless ? 0 : EGL_PBUFFER_BIT,
        EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
        EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
        EGL_NONE};
    // clang-format on
    EGLint count = 0;
    if (!eglChooseConfig(dpy, configAttribs, &config, 1, &count))
      throw EglError(failed("eglChooseConfig"));
    if (count == 0) throw EglError("eglChooseConfig found no OpenGL-renderable config");
  }

  // EGL 1.5 names the attributes itself; on 1.4 the KHR/EXT extension tokens carry the same
  // meaning (EGL_KHR_create_context, EGL_EXT_create_context_robustness).
  auto attribs = [&](bool robust) {
    // clang-format off
    std::vector<EGLint> a = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT};
    // clang-format on
    if (debug) {
      if (eglVersion >= 15)
        a.insert(a.end(), {EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE});
      else
        a.insert(a.end(), {EGL_CONTEXT_FLAGS_KHR, EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR});
    }
    // Only the reset notification strategy, not robust buffer access: the latter costs bounds
    // checks on every access on some hardware, and we only need to learn about a lost context.
    if (robust) {
      a.insert(a.end(), {eglVersion >= 15 ? EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY
                                          : EGL_CONTEXT_OPENGL_RESET_NOTIFICATION_STRATEGY_EXT,
                         EGL_LOSE_CONTEXT_ON_RESET});
    }
    a.push_back(EGL_NONE);
    return a;
  };
  const bool tryRobust = eglVersion >= 15 || robustnessExt;
  if (tryRobust) {
    impl->context = eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs(true).data());
    impl->loseContextOnReset = impl->context != EGL_NO_CONTEXT;
  }
  if (impl->context == EGL_NO_CONTEXT) {
    // Drivers may refuse the reset strategy (EGL_BAD_MATCH / EGL_BAD_ATTRIBUTE); a context without
    // reset notification is still a working context.
    impl->context = eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs(false).data());
    if (impl->context == EGL_NO_CONTEXT)
      throw EglError(failed("eglCreateContext(OpenGL 4.5 core)"));
  }

  if (!surfaceless) {
    const EGLint pbufferAttribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    impl->surface = eglCreatePbufferSurface(dpy, config, pbufferAttribs);
    if (impl->surface == EGL_NO_SURFACE) throw EglError(failed("eglCreatePbufferSurface(1x1)"));
  }
  if (!eglMakeCurrent(dpy, impl->surface, impl->surface, impl->context))
    throw EglError(failed("eglMakeCurrent"));

  // A driver may hand out a compatible higher version, never a lower one (EGL 1.5 section 3.7.1.1),
  // but check what we actually got rather than trust it.
  const int glVersion = epoxy_gl_version();
  GLint profile = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  if (glVersion < 45 || !(profile & GL_CONTEXT_CORE_PROFILE_BIT))
    throw EglError("context reports OpenGL " + glString(GL_VERSION) + ", need 4.5 core");

  impl->resetStatusAvailable = glVersion >= 45 || epoxy_has_gl_extension("GL_KHR_robustness");

  if (debug) {
    // Synchronous output makes the callback run inside the offending call, so a breakpoint or a
    // log line sits next to the call that caused it (KHR_debug, "Synchronous and Asynchronous").
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(logDebugMessage, nullptr);
    // Notifications (push/pop group echoes, driver chatter) would drown the useful messages.
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DEBUG_SEVERITY_NOTIFICATION, 0, nullptr,
                          GL_FALSE);
  }
  return impl;
}

std::unique_ptr<EglDevice> EglDevice::create(const DeviceOptions& options) {
  const bool debug = options.debug || kDebugByDefault || debugRequestedByEnvironment();
  const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (clientExt == nullptr)
    throw EglError(std::string(kCreate) + ": " + failed("eglQueryString(EGL_NO_DISPLAY)") +
                   " (EGL_EXT_client_extensions missing)");
  const bool canEnumerate = hasToken(clientExt, "EGL_EXT_device_enumeration") ||
                            hasToken(clientExt, "EGL_EXT_device_base");
  const bool canQuery =
      hasToken(clientExt, "EGL_EXT_device_query") || hasToken(clientExt, "EGL_EXT_device_base");
  const bool devicePlatform = hasToken(clientExt, "EGL_EXT_platform_device");
  const bool surfacelessPlatform = hasToken(clientExt, "EGL_MESA_platform_surfaceless");
  if (!hasToken(clientExt, "EGL_EXT_platform_base"))
    throw EglError(std::string(kCreate) + ": EGL_EXT_platform_base is unavailable");

  // --- Enumerate devices --------------------------------------------------------------------
  std::vector<Candidate> devices;
  std::string noDevicesWhy;
  if (!canEnumerate || !devicePlatform) {
    noDevicesWhy = !canEnumerate ? "EGL_EXT_device_enumeration unavailable"
                                 : "EGL_EXT_platform_device unavailable";
  } else {
    EGLint count = 0;
    if (!eglQueryDevicesEXT(0, nullptr, &count)) {
      noDevicesWhy = failed("eglQueryDevicesEXT");
    } else {
      std::vector<EGLDeviceEXT> handles(static_cast<std::size_t>(std::max(count, 0)));
      if (count > 0 && !eglQueryDevicesEXT(count, handles.data(), &count))
        throw EglError(std::string(kCreate) + ": " + failed("eglQueryDevicesEXT"));
      handles.resize(static_cast<std::size_t>(std::max(count, 0)));
      for (std::size_t i = 0; i < handles.size(); ++i) {
        Candidate c;
        c.device = handles[i];
        c.index = static_cast<int>(i);
        if (canQuery) {
          const char* e = eglQueryDeviceStringEXT(handles[i], EGL_EXTENSIONS);
          c.extensions = e ? e : "";
        }
        c.software = hasToken(c.extensions.c_str(), "EGL_MESA_device_software");
        devices.push_back(std::move(c));
      }
      if (devices.empty()) noDevicesWhy = "eglQueryDevicesEXT found no devices";
    }
  }

  // --- Decide the order to try them in -------------------------------------------------------
  std::vector<Candidate> order;
  std::string why;  // the reason, completed below with what was skipped
  if (options.index) {
    const int i = *options.index;
    if (devices.empty())
      throw EglError(std::string(kCreate) + ": device index " + std::to_string(i) +
                     " requested but no EGL device is enumerable (" + noDevicesWhy + ")");
    if (i < 0 || i >= static_cast<int>(devices.size()))
      throw EglError(std::string(kCreate) + ": device index " + std::to_string(i) +
                     " out of range: " + std::to_string(devices.size()) + " EGL device(s) found");
    order.push_back(devices[static_cast<std::size_t>(i)]);
    why = "requested device index " + std::to_string(i);
  } else if (options.cudaDevice) {
    const int want = *options.cudaDevice;
    std::string seen;
    for (const auto& c : devices) {
      if (!hasToken(c.extensions.c_str(), "EGL_NV_device_cuda")) continue;
      EGLAttrib cuda = -1;
      if (eglQueryDeviceAttribEXT(c.device, EGL_CUDA_DEVICE_NV, &cuda)) {
        seen += (seen.empty() ? "" : ", ") + std::to_string(cuda);
        if (cuda == want) order.push_back(c);
      }
    }
    if (order.empty())
      throw EglError(std::string(kCreate) + ": no EGL device has EGL_CUDA_DEVICE_NV " +
                     std::to_string(want) + " (CUDA ids offered: " +
                     (seen.empty() ? "none, no device has EGL_NV_device_cuda" : seen) + ")");
    why = "requested CUDA device " + std::to_string(want);
  } else {
    // Hardware first, each group in enumeration order; then Mesa's surfaceless platform, which
    // works where the device platform does not (older Mesa, no EGL_EXT_device_enumeration).
    for (const auto& c : devices)
      if (!c.software) order.push_back(c);
    for (const auto& c : devices)
      if (c.software) order.push_back(c);
    if (surfacelessPlatform) {
      Candidate s;
      s.platform = EGL_PLATFORM_SURFACELESS_MESA;
      order.push_back(s);
    }
    if (order.empty())
      throw EglError(std::string(kCreate) + ": no EGL device (" + noDevicesWhy +
                     ") and EGL_MESA_platform_surfaceless unavailable");
  }

  // --- Try them ------------------------------------------------------------------------------
  std::vector<std::string> skipped;
  for (const auto& c : order) {
    std::unique_ptr<Impl> impl;
    try {
      impl = Impl::open(c, debug);
    } catch (const EglError& e) {
      skipped.push_back(c.label() + ": " + e.what());
      continue;
    }
    DeviceInfo info;
    info.vendor = glString(GL_VENDOR);
    info.renderer = glString(GL_RENDERER);
    info.version = glString(GL_VERSION);
    info.glslVersion = glString(GL_SHADING_LANGUAGE_VERSION);
    if (!options.nameContains.empty() && !containsIgnoreCase(info.renderer, options.nameContains) &&
        !containsIgnoreCase(info.vendor, options.nameContains)) {
      skipped.push_back(c.label() + ": \"" + info.renderer + "\" / \"" + info.vendor +
                        "\" does not match");
      continue;  // impl's destructor releases the context and the display
    }
    info.platform = c.platform == EGL_PLATFORM_SURFACELESS_MESA ? "surfaceless" : "device";
    info.deviceIndex = c.index;
    info.deviceExtensions = c.extensions;
    // The surfaceless platform does not say whether it is software; the renderer string does.
    info.software = c.software || containsIgnoreCase(info.renderer, "llvmpipe") ||
                    containsIgnoreCase(info.renderer, "softpipe") ||
                    containsIgnoreCase(info.renderer, "swrast");
    if (why.empty()) {
      if (!options.nameContains.empty())
        why = "renderer/vendor contains \"" + options.nameContains + "\"";
      else if (c.platform == EGL_PLATFORM_SURFACELESS_MESA)
        why = "surfaceless fallback: " +
              (devices.empty() ? noDevicesWhy : std::string("no enumerated device worked"));
      else if (!c.software)
        why = "first hardware device";
      else if (std::none_of(devices.begin(), devices.end(),
                            [](const Candidate& d) { return !d.software; }))
        why = "software fallback: no hardware EGL device";
      else
        why = "software fallback: no hardware device worked";
    }
    info.reason = why + " (" + c.label() + ")";
    if (!skipped.empty()) {
      info.reason += "; skipped ";
      for (std::size_t i = 0; i < skipped.size(); ++i) info.reason += (i ? "; " : "") + skipped[i];
    }
    if (!impl->loseContextOnReset) info.reason += "; no reset notification";
    if (containsIgnoreCase(info.renderer, "llvmpipe")) warmUpLlvmpipe();

    auto device = std::unique_ptr<EglDevice>(new EglDevice());
    device->impl_ = std::move(impl);
    device->info_ = std::move(info);
    return device;
  }

  std::string message = std::string(kCreate) + ": ";
  if (!options.nameContains.empty())
    message +=
        "no EGL device has a renderer or vendor containing \"" + options.nameContains + "\": ";
  else if (skipped.size() > 1)
    message += "no usable EGL device: ";
  for (std::size_t i = 0; i < skipped.size(); ++i) message += (i ? "; " : "") + skipped[i];
  throw EglError(message);
}

EglDevice::~EglDevice() = default;

void EglDevice::makeCurrent() {
  // The bound client API is per-thread state (EGL 1.5 section 3.7), so a new thread starts at the
  // default (OpenGL ES).
  if (!eglBindAPI(EGL_OPENGL_API))
    throw EglError("EglDevice::makeCurrent(): " + failed("eglBindAPI(EGL_OPENGL_API)"));
  if (!eglMakeCurrent(impl_->display, impl_->surface, impl_->surface, impl_->context))
    throw EglError("EglDevice::makeCurrent(): " + failed("eglMakeCurrent"));
}

void EglDevice::checkHealthy() const {
  // First, before any other EGL call resets it to EGL_SUCCESS.
  const EGLint pending = eglGetError();
  if (pending != EGL_SUCCESS)
    throw EglError(std::string("EglDevice::checkHealthy(): pending EGL error: ") +
                   eglErrorName(pending));
  if (eglGetCurrentContext() != impl_->context)
    throw EglError(
        "EglDevice::checkHealthy(): the context is not current on this thread "
        "(call makeCurrent() on the render thread)");
  if (impl_->resetStatusAvailable) {
    // GL 4.5 core section 2.3.2: non-zero once the context was lost; it must then be destroyed.
    const GLenum status = glGetGraphicsResetStatus();
    const char* name = nullptr;
    switch (status) {
      case GL_NO_ERROR: break;
      case GL_GUILTY_CONTEXT_RESET: name = "GL_GUILTY_CONTEXT_RESET"; break;
      case GL_INNOCENT_CONTEXT_RESET: name = "GL_INNOCENT_CONTEXT_RESET"; break;
      case GL_UNKNOWN_CONTEXT_RESET: name = "GL_UNKNOWN_CONTEXT_RESET"; break;
      default: name = "unknown reset status"; break;
    }
    if (name)
      throw EglError(std::string("EglDevice::checkHealthy(): context lost: "
                                 "glGetGraphicsResetStatus returned ") +
                     name);
  }
}

}  // namespace radiant
