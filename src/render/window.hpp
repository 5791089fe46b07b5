// The window front end (GLFW; compiled when SEAMLESS_HAS_GLFW). It owns a GL 4.1 core context,
// a Renderer on it, and a loop that steps the simulation, draws and shows the frame.
//
// Keys: Space pause/run, N one step while paused, G spawn the next configured object,
// 1 scene, 2 fluid, 3 rigid, 4 cloth, 5 particle spheres (layers on/off), F fluid SSFR/particles,
// V mesh/Kinect view, C orbit/fly camera, mouse drag rotate, wheel zoom, W A S D Q E fly,
// Esc quit. Per-pass GPU times are shown as bars at the bottom and as numbers in the title.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "render/draw_list.hpp"
#include "render/render_params.hpp"

namespace seamless {

class Renderer;

struct WindowCallbacks {
  std::function<void()> step;                  // advance the simulation one frame
  std::function<DrawList()> draw_list;         // what to draw now
  std::function<void()> spawn_next;            // the next configured object (key G)
  std::function<void(Renderer&)> before_draw;  // e.g. set_kinect_view with the newest frame
  std::function<void(Renderer&)> on_start;     // e.g. set_scene_mesh
  // Keys pressed before frame `frame` (GLFW key codes), handled as if typed: for scripted runs
  // and tests (a display server delivers no events to an unattended window).
  std::function<std::vector<int>(int frame)> scripted_keys;
};

struct WindowView {
  vec3 target{0.f, 0.f, 0.f};  // orbit centre
  float distance = 3.f;        // metres
  vec3 up{0.f, 1.f, 0.f};      // world up (against gravity)
};

// True when GLFW can open a window here (a display is present).
bool window_available();
// Runs until the window is closed. Throws seamless::Error if no window can be opened.
void run_window(const RenderParams& params, const std::string& title, const WindowCallbacks& cb,
                const WindowView& view = {});

}  // namespace seamless
