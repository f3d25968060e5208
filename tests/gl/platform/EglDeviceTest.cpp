// renderer/platform/EglDevice: device selection and the headless 4.5 core context, on whatever EGL
// device the machine offers (Mesa llvmpipe in CI).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <string>
#include <thread>

#include "tests/support/Expect.h"
#include "renderer/platform/EglDevice.h"

namespace radiant {
namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Designated initialisers would trip -Wmissing-field-initializers; these read as well.
DeviceOptions byName(std::string name) {
  DeviceOptions o;
  o.nameContains = std::move(name);
  return o;
}
DeviceOptions byIndex(int index) {
  DeviceOptions o;
  o.index = index;
  return o;
}
DeviceOptions byCuda(int id) {
  DeviceOptions o;
  o.cudaDevice = id;
  return o;
}
DeviceOptions withDebug() {
  DeviceOptions o;
  o.debug = true;
  return o;
}


TEST(EglDevice, DefaultContextIsOpenGL45Core) {
  auto device = EglDevice::create();
  const DeviceInfo& info = device->info();
  GLint major = 0, minor = 0, profile = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_GE(major * 10 + minor, 45) << info.version;
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  EXPECT_FALSE(info.vendor.empty());
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_NE(info.version.find("4."), std::string::npos) << info.version;
  EXPECT_EQ(info.version.find("Compatibility"), std::string::npos) << info.version;
  EXPECT_EQ(info.glslVersion.rfind("4.", 0), 0u) << info.glslVersion;
  EXPECT_TRUE(info.platform == "device" || info.platform == "surfaceless") << info.platform;
  EXPECT_EQ(info.deviceIndex < 0, info.platform == "surfaceless");
  EXPECT_FALSE(info.reason.empty());
  if (lower(info.renderer).find("llvmpipe") != std::string::npos) {
    EXPECT_TRUE(info.software);
  }
  std::fprintf(stderr, "device: %s | %s | %s | %s #%d | %s\n", info.renderer.c_str(),
               info.vendor.c_str(), info.version.c_str(), info.platform.c_str(), info.deviceIndex,
               info.reason.c_str());
  EXPECT_NO_THROW(device->checkHealthy());

  // Unless the reason says otherwise, a lost context is reported (checkHealthy relies on it).
  if (info.reason.find("no reset notification") == std::string::npos) {
    GLint strategy = 0;
    glGetIntegerv(GL_RESET_NOTIFICATION_STRATEGY, &strategy);
    EXPECT_EQ(strategy, GL_LOSE_CONTEXT_ON_RESET);
  }
}

// No device is assumed: the name asked for is a word of the default device's renderer string in the
// other case ("LLVMPIPE" under Mesa, "nvidia" for "NVIDIA H200/PCIe/SSE2").
std::string defaultRendererWord() {
  const std::string renderer = EglDevice::create()->info().renderer;
  std::string word, best;
  for (char c : renderer + " ") {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      word += c;
    } else {
      if (best.empty() && word.size() >= 3) best = word;
      word.clear();
    }
  }
  for (auto& c : best)
    c = static_cast<char>(std::islower(static_cast<unsigned char>(c)) ? std::toupper(static_cast<unsigned char>(c))
                                                                      : std::tolower(static_cast<unsigned char>(c)));
  return best;
}

TEST(EglDevice, ChoosesByRendererSubstringCaseInsensitively) {
  const std::string word = defaultRendererWord();
  ASSERT_FALSE(word.empty());
  auto device = EglDevice::create(byName(word));
  EXPECT_NE(lower(device->info().renderer).find(lower(word)), std::string::npos) << device->info().renderer;
  if (lower(device->info().renderer).find("llvmpipe") != std::string::npos) {
    EXPECT_TRUE(device->info().software);
  }
  EXPECT_NE(device->info().reason.find(word), std::string::npos) << device->info().reason;
}

TEST(EglDevice, BogusNameThrowsNamingTheRequest) {
  const std::string word = defaultRendererWord();
  const std::string message = testing::thrownMessage<EglError>([] { EglDevice::create(byName("no-such-gpu-7f3a")); });
  EXPECT_EQ(message.rfind("EglDevice::create(): ", 0), 0u) << message;
  EXPECT_NE(message.find("\"no-such-gpu-7f3a\""), std::string::npos) << message;
  // It lists what it saw, so the operator can pick a better substring.
  EXPECT_NE(lower(message).find(lower(word)), std::string::npos) << message;
}

TEST(EglDevice, ChoosesByIndex) {
  auto device = EglDevice::create(byIndex(0));
  EXPECT_EQ(device->info().platform, "device");
  EXPECT_EQ(device->info().deviceIndex, 0);
  EXPECT_EQ(device->info().reason.rfind("requested device index 0", 0), 0u)
      << device->info().reason;
}

TEST(EglDevice, BadIndexThrows) {
  for (int index : {999, -1}) {
    const std::string message = testing::thrownMessage<EglError>([&] { EglDevice::create(byIndex(index)); });
    EXPECT_EQ(message.rfind("EglDevice::create(): device index " + std::to_string(index), 0), 0u)
        << message;
    EXPECT_NE(message.find("out of range"), std::string::npos) << message;
  }
}

TEST(EglDevice, CudaDeviceNeedsNvDriver) {
  // With an NVIDIA driver this picks CUDA device 0; elsewhere it must fail cleanly, not fall back.
  try {
    auto device = EglDevice::create(byCuda(0));
    EXPECT_NE(device->info().deviceExtensions.find("EGL_NV_device_cuda"), std::string::npos);
  } catch (const EglError& e) {
    EXPECT_NE(std::string(e.what()).find("EGL_CUDA_DEVICE_NV 0"), std::string::npos) << e.what();
  }
}

TEST(EglDevice, TwoDevicesOnOneDisplayDoNotTerminateEachOther) {
  auto first = EglDevice::create(byIndex(0));
  {
    auto second = EglDevice::create(byIndex(0));
    EXPECT_NE(glGetString(GL_RENDERER), nullptr);
  }  // second's destructor must not eglTerminate the display the first still uses
  first->makeCurrent();
  EXPECT_NO_THROW(first->checkHealthy());
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  EXPECT_NE(buffer, 0u);
  glDeleteBuffers(1, &buffer);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(EglDevice, CreateDestroyRepeatedly) {
  for (int i = 0; i < 3; ++i) {
    auto device = EglDevice::create();
    EXPECT_NO_THROW(device->checkHealthy());
  }
}

TEST(EglDevice, OtherThreadSeesContextNotCurrentAndCannotStealIt) {
  auto device = EglDevice::create();
  std::string healthMessage, makeCurrentMessage;
  std::thread([&] {
    healthMessage = testing::thrownMessage<EglError>([&] { device->checkHealthy(); });
    // The context is current on the main thread; EGL refuses to bind it twice (EGL 1.5 3.7.3).
    makeCurrentMessage = testing::thrownMessage<EglError>([&] { device->makeCurrent(); });
  }).join();
  EXPECT_NE(healthMessage.find("not current"), std::string::npos) << healthMessage;
  EXPECT_EQ(makeCurrentMessage, "EglDevice::makeCurrent(): eglMakeCurrent failed: EGL_BAD_ACCESS");
  EXPECT_NO_THROW(device->checkHealthy());
}

TEST(EglDevice, DebugContextLogsErrorsToStderr) {
  auto device = EglDevice::create(withDebug());
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  EXPECT_TRUE(flags & GL_CONTEXT_FLAG_DEBUG_BIT);
  ::testing::internal::CaptureStderr();
  glEnable(0xFFFF);  // GL_INVALID_ENUM, reported synchronously through the debug callback
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_INVALID_ENUM));
  EXPECT_NE(log.find("[gl high api error"), std::string::npos) << log;
}

TEST(EglDevice, ErrorNames) {
  EXPECT_STREQ(eglErrorName(0x3001), "EGL_NOT_INITIALIZED");
  EXPECT_STREQ(eglErrorName(0x3002), "EGL_BAD_ACCESS");
  EXPECT_STREQ(eglErrorName(0x300E), "EGL_CONTEXT_LOST");
  EXPECT_STREQ(eglErrorName(0x1234), "unknown EGL error");
}

}  // namespace
}  // namespace radiant
