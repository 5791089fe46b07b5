// GLFW window front end (see window.hpp).
#include "render/window.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "render/renderer.hpp"

namespace seamless {
namespace {

struct Ui {
  bool paused = false, step_once = false, spawn = false, fly = false;
  OrbitState orbit;
  vec3 fly_pos{0.f, 0.f, 0.f};
  float fly_yaw = 0.f, fly_pitch = 0.f;
  double last_x = 0.0, last_y = 0.0;
  bool dragging = false;
  RenderParams* params = nullptr;
  vec3 up{0.f, 1.f, 0.f};
};

Ui& ui_of(GLFWwindow* w) { return *static_cast<Ui*>(glfwGetWindowUserPointer(w)); }

vec3 fly_forward(const Ui& u) {
  // Same basis as the orbit: yaw about `up`, pitch above the horizon.
  OrbitState o;
  o.yaw = u.fly_yaw, o.pitch = u.fly_pitch, o.distance = 1.f;
  return o.eye(u.up);
}

void press(GLFWwindow* w, int key) {
  Ui& u = ui_of(w);
  RenderParams& p = *u.params;
  switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, GLFW_TRUE); break;
    case GLFW_KEY_SPACE: u.paused = !u.paused; break;
    case GLFW_KEY_N: u.step_once = true; break;
    case GLFW_KEY_G: u.spawn = true; break;
    case GLFW_KEY_1: p.show_scene = !p.show_scene; break;
    case GLFW_KEY_2: p.show_fluid = !p.show_fluid; break;
    case GLFW_KEY_3: p.show_rigid = !p.show_rigid; break;
    case GLFW_KEY_4: p.show_cloth = !p.show_cloth; break;
    case GLFW_KEY_5: p.show_particles = !p.show_particles; break;
    case GLFW_KEY_F: p.fluid = p.fluid == FluidDraw::ssfr ? FluidDraw::particles : FluidDraw::ssfr; break;
    case GLFW_KEY_V: p.view = p.view == RenderView::mesh ? RenderView::kinect : RenderView::mesh; break;
    case GLFW_KEY_C:
      if (!u.fly) {  // start flying from where the orbit camera is, looking the same way
        u.fly_pos = u.orbit.eye(u.up);
        u.fly_yaw = u.orbit.yaw + 3.14159265f, u.fly_pitch = -u.orbit.pitch;
      }
      u.fly = !u.fly;
      break;
    default: break;
  }
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action == GLFW_PRESS) press(w, key);
}

void on_mouse(GLFWwindow* w, double x, double y) {
  Ui& u = ui_of(w);
  if (u.dragging) {
    const float dx = static_cast<float>(x - u.last_x) * 0.005f, dy = static_cast<float>(y - u.last_y) * 0.005f;
    if (u.fly) u.fly_yaw -= dx, u.fly_pitch = std::clamp(u.fly_pitch - dy, -1.5f, 1.5f);
    else u.orbit.yaw -= dx, u.orbit.pitch = std::clamp(u.orbit.pitch + dy, -1.5f, 1.5f);
  }
  u.last_x = x, u.last_y = y;
}

void on_button(GLFWwindow* w, int button, int action, int) {
  if (button == GLFW_MOUSE_BUTTON_LEFT) ui_of(w).dragging = action == GLFW_PRESS;
}

void on_scroll(GLFWwindow* w, double, double dy) {
  Ui& u = ui_of(w);
  u.orbit.distance = std::max(0.05f, u.orbit.distance * std::pow(0.9f, static_cast<float>(dy)));
}

void fly_keys(GLFWwindow* w, Ui& u, float dt) {
  const vec3 f = fly_forward(u), r = normalize(cross(f, u.up));
  const float s = 1.5f * dt;  // metres per second
  auto held = [&](int k) { return glfwGetKey(w, k) == GLFW_PRESS; };
  if (held(GLFW_KEY_W)) u.fly_pos += f * s;
  if (held(GLFW_KEY_S)) u.fly_pos -= f * s;
  if (held(GLFW_KEY_D)) u.fly_pos += r * s;
  if (held(GLFW_KEY_A)) u.fly_pos -= r * s;
  if (held(GLFW_KEY_E)) u.fly_pos += u.up * s;
  if (held(GLFW_KEY_Q)) u.fly_pos -= u.up * s;
}

// Per-pass GPU time as bars along the bottom, 1 ms = 40 pixels, one colour per pass.
void draw_timing_bars(const std::vector<RenderTiming>& t, int fb_w) {
  glEnable(GL_SCISSOR_TEST);
  int x = 4;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const int len = std::max(1, static_cast<int>(t[i].ms * 40.0));
    const float hue = static_cast<float>(i) / static_cast<float>(std::max<std::size_t>(t.size(), 1));
    glScissor(x, 4, std::min(len, fb_w - x), 10);
    glClearColor(0.5f + 0.5f * std::cos(6.28f * hue), 0.5f + 0.5f * std::cos(6.28f * (hue - 0.33f)),
                 0.5f + 0.5f * std::cos(6.28f * (hue - 0.67f)), 1.f);
    glClear(GL_COLOR_BUFFER_BIT);
    x += len + 2;
    if (x >= fb_w) break;
  }
  glDisable(GL_SCISSOR_TEST);
}

std::string title_with_timings(const std::string& title, const std::vector<RenderTiming>& t, double frame_ms,
                               bool paused) {
  std::string s = title + (paused ? "  [paused]" : "");
  char b[64];
  std::snprintf(b, sizeof b, "  %.1f ms/frame |", frame_ms);
  s += b;
  for (const RenderTiming& r : t) {
    std::snprintf(b, sizeof b, " %s %.2f", r.pass.c_str(), r.ms);
    s += b;
  }
  return s;
}

GLFWwindow* open_window(const RenderParams& p, const std::string& title) {
  if (!glfwInit()) throw Error("render: GLFW could not initialise (no display? use render.mode: headless)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* w = glfwCreateWindow(p.width, p.height, title.c_str(), nullptr, nullptr);
  if (!w) {
    glfwTerminate();
    throw Error("render: no OpenGL 4.1 core window could be opened (use render.mode: headless)");
  }
  glfwMakeContextCurrent(w);
  glfwSwapInterval(1);
  return w;
}

}  // namespace

bool window_available() {
  if (!glfwInit()) return false;
  glfwTerminate();
  return true;
}

void run_window(const RenderParams& params, const std::string& title, const WindowCallbacks& cb,
                const WindowView& view) {
  RenderParams p = params;
  GLFWwindow* w = open_window(p, title);
  Ui ui;
  ui.params = &p;
  ui.up = normalize(view.up);
  ui.orbit.target = view.target, ui.orbit.distance = view.distance;
  glfwSetWindowUserPointer(w, &ui);
  glfwSetKeyCallback(w, on_key);
  glfwSetCursorPosCallback(w, on_mouse);
  glfwSetMouseButtonCallback(w, on_button);
  glfwSetScrollCallback(w, on_scroll);
  try {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(w, &fw, &fh);
    Renderer r(p, fw, fh, Renderer::UseCurrentContext{});
    if (cb.on_start) cb.on_start(r);
    auto last = std::chrono::steady_clock::now();
    int frame = 0;
    while (!glfwWindowShouldClose(w) && !interrupted()) {  // Ctrl-C closes the window as Esc does
      const auto now = std::chrono::steady_clock::now();
      const double dt = std::chrono::duration<double>(now - last).count();
      last = now;
      glfwPollEvents();
      if (cb.scripted_keys)
        for (int key : cb.scripted_keys(frame)) press(w, key);
      if (ui.spawn && cb.spawn_next) cb.spawn_next();
      if ((!ui.paused || ui.step_once) && cb.step) cb.step();
      ui.spawn = ui.step_once = false;
      glfwGetFramebufferSize(w, &fw, &fh);
      r.resize(fw, fh);
      r.params() = p;
      if (cb.before_draw) cb.before_draw(r);
      if (ui.fly) fly_keys(w, ui, static_cast<float>(dt));
      const vec3 eye = ui.fly ? ui.fly_pos : ui.orbit.eye(ui.up);
      const vec3 at = ui.fly ? ui.fly_pos + fly_forward(ui) : ui.orbit.target;
      const RenderCamera cam = RenderCamera::look_at(eye, at, ui.up, p.fov_y, fw, fh, p.znear, p.zfar);
      r.draw(cb.draw_list ? cb.draw_list() : DrawList{}, cam);
      r.blit_to(0, fw, fh);
      draw_timing_bars(r.timings(), fw);
      if (++frame % 15 == 0) glfwSetWindowTitle(w, title_with_timings(title, r.timings(), dt * 1e3, ui.paused).c_str());
      glfwSwapBuffers(w);
    }
  } catch (...) {
    glfwDestroyWindow(w);
    glfwTerminate();
    throw;
  }
  glfwDestroyWindow(w);
  glfwTerminate();
}

}  // namespace seamless
