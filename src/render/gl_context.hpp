// Headless OpenGL through EGL: no window, no X server. The renderer draws into its own
// framebuffer objects, so the context needs no surface (EGL_KHR_surfaceless_context).
//
// Display search order: an EGL device (EGL_EXT_platform_device; NVIDIA's EGL on the GPU machine,
// hardware devices first), then Mesa's surfaceless platform (llvmpipe in CI), then the default
// display. EGL_PLATFORM=surfaceless in the environment is honoured by Mesa for the last one.
#pragma once
#include <memory>
#include <string>

namespace seamless {

struct GlInfo {
  std::string vendor, renderer, version, egl_path;  // egl_path: which display search step worked
};

class HeadlessContext {
 public:
  // Creates a desktop OpenGL 4.1+ core context and makes it current on this thread. Throws
  // seamless::Error saying what failed (no EGL display, no GL 4 core context) and what to install.
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  void make_current();
  const GlInfo& info() const;

  // True when a headless context can be created here (tests skip otherwise); `why` gets the reason.
  static bool available(std::string* why = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace seamless
