// EGL display and context creation (see gl_context.hpp for the search order).
#include "render/gl_context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace seamless {
namespace {

bool has_ext(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

bool try_init(EGLDisplay d) {
  EGLint major = 0, minor = 0;
  return d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor) == EGL_TRUE;
}

// EGL devices, hardware first: Mesa lists its software rasteriser as a device too.
void device_displays(std::vector<std::pair<std::string, EGLDisplay>>& out) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_ext(client, "EGL_EXT_platform_device") || !has_ext(client, "EGL_EXT_device_enumeration")) return;
  EGLint n = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &n) || n <= 0) return;
  std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(n));
  eglQueryDevicesEXT(n, devices.data(), &n);
  for (int pass = 0; pass < 2; ++pass)
    for (EGLDeviceEXT dev : devices) {
      const char* ext = eglQueryDeviceStringEXT(dev, EGL_EXTENSIONS);
      if (has_ext(ext, "EGL_MESA_device_software") != (pass == 1)) continue;
      out.emplace_back(pass == 0 ? "EGL device" : "EGL software device",
                       eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, dev, nullptr));
    }
}

// Candidate displays in the order of gl_context.hpp (not yet initialised).
std::vector<std::pair<std::string, EGLDisplay>> candidate_displays() {
  std::vector<std::pair<std::string, EGLDisplay>> out;
  device_displays(out);
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (has_ext(client, "EGL_MESA_platform_surfaceless"))
    out.emplace_back("Mesa surfaceless",
                     eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
  out.emplace_back("default display", eglGetDisplay(EGL_DEFAULT_DISPLAY));
  return out;
}

// A desktop GL core context, the newest of 4.5 .. 4.1 the driver gives.
EGLContext create_context(EGLDisplay d) {
  if (!eglBindAPI(EGL_OPENGL_API)) return EGL_NO_CONTEXT;
  const EGLint cfg_attr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig cfg = nullptr;
  EGLint ncfg = 0;
  // We draw into our own framebuffer objects, so no config is needed where the driver allows it.
  if (!eglChooseConfig(d, cfg_attr, &cfg, 1, &ncfg) || ncfg < 1) {
    if (!has_ext(eglQueryString(d, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) return EGL_NO_CONTEXT;
    cfg = EGL_NO_CONFIG_KHR;
  }
  for (int minor : {5, 3, 1}) {
    const EGLint attr[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, minor, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, cfg, EGL_NO_CONTEXT, attr);
    if (c != EGL_NO_CONTEXT) return c;
  }
  return EGL_NO_CONTEXT;
}

const char* gl_str(GLenum e) {
  const auto* s = reinterpret_cast<const char*>(glGetString(e));
  return s ? s : "?";
}

}  // namespace

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GlInfo info;
};

HeadlessContext::HeadlessContext() : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  std::string tried;
  for (auto& [path, d] : candidate_displays()) {
    tried += (tried.empty() ? "" : ", ") + path;
    if (!try_init(d)) {
      tried += " (no display)";
      continue;
    }
    EGLContext c = create_context(d);
    if (c == EGL_NO_CONTEXT) {
      tried += " (no OpenGL 4.1+ core context)";
      eglTerminate(d);
      continue;
    }
    m.display = d, m.context = c, m.info.egl_path = path;
    break;
  }
  if (m.context == EGL_NO_CONTEXT)
    throw Error("render: no EGL display gives an OpenGL 4.1+ core context (tried " + tried +
                "). Install Mesa's EGL (apt-get install libegl-mesa0 libgl1-mesa-dri) or the NVIDIA "
                "driver's EGL library");
  make_current();
  m.info.vendor = gl_str(GL_VENDOR);
  m.info.renderer = gl_str(GL_RENDERER);
  m.info.version = gl_str(GL_VERSION);
}

HeadlessContext::~HeadlessContext() {
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(impl_->display, impl_->context);
  eglTerminate(impl_->display);
}

void HeadlessContext::make_current() {
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context)) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(eglGetError()));
    throw Error(std::string("render: eglMakeCurrent failed (EGL error ") + code +
                "); the driver must support EGL_KHR_surfaceless_context");
  }
}

const GlInfo& HeadlessContext::info() const { return impl_->info; }

bool HeadlessContext::available(std::string* why) {
  try {
    HeadlessContext c;
    return true;
  } catch (const Error& e) {
    if (why) *why = e.what();
    return false;
  }
}

}  // namespace seamless
