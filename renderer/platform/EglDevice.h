#pragma once
// Headless OpenGL 4.5 core context through EGL, with no window system.
//
// Selection order (DeviceOptions empty): enumerate EGL devices (EGL_EXT_device_enumeration), prefer a
// hardware device (one without EGL_MESA_device_software), fall back to Mesa's software device, then
// to the surfaceless platform (EGL_MESA_platform_surfaceless). A request can choose by index, by a
// substring of the renderer or vendor string, or by CUDA device id (EGL_NV_device_cuda).
//
// Every failure throws EglError naming the call and the decoded error:
//   "EglDevice::create(): eglInitialize failed: EGL_NOT_INITIALIZED".

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace radiant {

struct EglError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

const char* eglErrorName(int error);  // EGL_BAD_ACCESS ...

struct DeviceOptions {
  std::optional<int> index;        // EGL device index
  std::string nameContains;        // substring of GL_RENDERER or GL_VENDOR (case-insensitive)
  std::optional<int> cudaDevice;   // EGL_CUDA_DEVICE_NV
  bool debug = false;              // debug context + KHR_debug message log to stderr
};

struct DeviceInfo {
  std::string vendor, renderer, version, glslVersion;
  std::string platform;  // "device" or "surfaceless"
  int deviceIndex = -1;  // -1 on the surfaceless platform
  std::string deviceExtensions;
  std::string reason;    // why this device was chosen ("first hardware device", "software fallback: ...")
  bool software = false;
};

// Owns the EGL display and a current GL 4.5 core context on the creating thread. Not copyable.
class EglDevice {
public:
  static std::unique_ptr<EglDevice> create(const DeviceOptions& options = {});
  ~EglDevice();
  EglDevice(const EglDevice&) = delete;
  EglDevice& operator=(const EglDevice&) = delete;

  const DeviceInfo& info() const { return info_; }
  void makeCurrent();  // re-binds the context to the calling thread
  // Throws EglError if the context was lost (GL_KHR_robustness reset status) or EGL reports an error.
  void checkHealthy() const;

private:
  EglDevice() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  DeviceInfo info_;
};

}  // namespace radiant
