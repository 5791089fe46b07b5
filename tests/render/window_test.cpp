// The GLFW window front end, run for a few frames on a virtual X server (Xvfb, Mesa's GLX) with a
// scripted key sequence: pause, single step, toggle a layer, spawn, resume, quit. Skips when no
// display is set and Xvfb is not installed (Debian package xvfb), or GLFW cannot open a window.
#include <gtest/gtest.h>

#include "seamless/build_config.hpp"

#if SEAMLESS_HAS_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "core/phase.hpp"
#include "render/renderer.hpp"
#include "render/window.hpp"

namespace seamless {
namespace {

// $DISPLAY if set; otherwise an Xvfb started on a free display number, stopped at the end.
class VirtualDisplay {
 public:
  VirtualDisplay() {
    if (std::getenv("DISPLAY")) {
      ok_ = true;
      return;
    }
    for (int n = 97; n < 130 && !ok_; ++n) {
      const std::string sock = "/tmp/.X11-unix/X" + std::to_string(n), lock = "/tmp/.X" + std::to_string(n) + "-lock";
      if (std::filesystem::exists(sock) || std::filesystem::exists(lock)) continue;
      const std::string name = ":" + std::to_string(n);
      pid_ = fork();
      if (pid_ == 0) {
        // -noreset: Xvfb otherwise resets when its last client leaves (window_available() connects and
        // disconnects), and the next connection can land in the reset and fail.
        execlp("Xvfb", "Xvfb", name.c_str(), "-screen", "0", "320x240x24", "-nolisten", "tcp", "-noreset",
               static_cast<char*>(nullptr));
        _exit(127);  // not installed
      }
      int status = 0;
      bool exited = false;
      for (int i = 0; i < 100 && !std::filesystem::exists(sock); ++i) {
        if ((exited = waitpid(pid_, &status, WNOHANG) == pid_)) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      if (exited) {
        pid_ = -1;
        if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return;  // no Xvfb installed
        continue;                                                     // display taken: next one
      }
      ok_ = std::filesystem::exists(sock);
      if (ok_) {
        setenv("DISPLAY", name.c_str(), 1);
      } else {  // still starting after 5 s: give up on it
        kill(pid_, SIGTERM);
        waitpid(pid_, nullptr, 0);
        pid_ = -1;
      }
    }
  }
  ~VirtualDisplay() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
    unsetenv("DISPLAY");
  }
  bool ok() const { return ok_; }

 private:
  pid_t pid_ = -1;
  bool ok_ = false;
};

TEST(RenderWindow, ScriptedKeysPauseStepToggleSpawnAndCloseCleanly) {
  VirtualDisplay display;
  if (!display.ok()) GTEST_SKIP() << "no DISPLAY and no Xvfb to start (apt-get install xvfb)";
  // The socket appears before the server accepts clients: give it up to 2 s.
  bool available = false;
  for (int i = 0; i < 20 && !(available = window_available()); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (!available) GTEST_SKIP() << "GLFW cannot open the display " << std::getenv("DISPLAY");
  RenderParams p;
  p.width = 160, p.height = 120;
  // A small block of fluid in front of the orbit camera, so every SSFR pass runs.
  std::vector<vec3> x;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) x.push_back({0.04f * i - 0.06f, 0.04f * j - 0.06f, 0.04f * k - 0.06f});
  std::vector<std::uint32_t> ph(x.size(), phase::kFluid);
  int steps = 0, spawns = 0;
  std::vector<bool> fluid_shown;
  std::vector<std::size_t> passes;
  WindowCallbacks cb;
  cb.step = [&] { ++steps; };
  cb.spawn_next = [&] { ++spawns; };
  cb.draw_list = [&] {
    DrawList d;
    d.positions = x, d.phases = ph, d.particle_radius = 0.02f;
    return d;
  };
  cb.before_draw = [&](Renderer& r) {
    fluid_shown.push_back(r.params().show_fluid);
    passes.push_back(r.timings().size());  // of the frame before the previous one (read a frame late)
  };
  cb.scripted_keys = [](int frame) -> std::vector<int> {
    switch (frame) {
      case 0: return {GLFW_KEY_SPACE};   // pause
      case 2: return {GLFW_KEY_N};       // one step while paused
      case 3: return {GLFW_KEY_2};       // fluid layer off
      case 4: return {GLFW_KEY_G};       // spawn the next object
      case 5: return {GLFW_KEY_SPACE};   // run again
      case 8: return {GLFW_KEY_ESCAPE};  // quit after this frame
      default: return {};
    }
  };
  try {
    run_window(p, "seamless window test", cb, WindowView{{0.f, 0.f, 0.f}, 0.6f, {0.f, 1.f, 0.f}});
  } catch (const std::exception& e) {
    FAIL() << "run_window threw: " << e.what();
  }
  // Frames 0-8 ran; steps: frame 2 (N), then frames 5-8 running.
  ASSERT_EQ(fluid_shown.size(), 9u);
  EXPECT_EQ(steps, 5);
  EXPECT_EQ(spawns, 1);
  EXPECT_TRUE(fluid_shown[2]);
  EXPECT_FALSE(fluid_shown[3]);
  EXPECT_FALSE(fluid_shown[8]);
  // Frames 0 and 1 drew the fluid: before frame 2 the timings (frame 0's) include its five passes.
  EXPECT_GE(passes[2], 7u);
  // GLFW was shut down cleanly: it starts again.
  EXPECT_TRUE(window_available());
}

}  // namespace
}  // namespace seamless
#endif
