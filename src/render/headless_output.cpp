#include "render/headless_output.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/log.hpp"
#include "io/png_io.hpp"
#include "render/renderer.hpp"

extern char** environ;  // the environment ffmpeg inherits (POSIX)

namespace seamless {
namespace fs = std::filesystem;

std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  for (std::string dir; std::getline(ss, dir, ':');) {
    const fs::path exe = fs::path(dir.empty() ? "." : dir) / "ffmpeg";
    std::error_code ec;
    if (fs::is_regular_file(exe, ec) && access(exe.c_str(), X_OK) == 0) return exe.string();
  }
  return "";
}

namespace {
std::string numbered(std::int64_t i) {
  char b[32];
  std::snprintf(b, sizeof b, "%06lld", static_cast<long long>(i));
  return b;
}
}  // namespace

HeadlessOutput::HeadlessOutput(const std::string& dir, const RenderParams& params) : dir_(dir), p_(params) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (p_.write_frames) fs::create_directories(dir_ + "/frames", ec);
  if (p_.stage_images) fs::create_directories(dir_ + "/stages", ec);
  if (ec) throw Error("render: cannot create the output folder " + dir_ + ": " + ec.message());
}

HeadlessOutput::~HeadlessOutput() {
  try {
    finish();
  } catch (...) {
  }
}

// ffmpeg reads raw RGB24 frames from stdin; H.264 in yuv420p wants even sizes, so pad by one.
// It is started with an argument vector (posix_spawn), never through a shell: any output path,
// quotes and spaces included, reaches it as given. It runs in a session of its own (setsid), so
// that a Ctrl-C meant for the run (which then finishes its frame and writes its outputs) does not
// kill the encoder mid-file.
void HeadlessOutput::open_video(int w, int h) {
  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) {
    spdlog::warn("render.video: ffmpeg is not installed (apt-get install ffmpeg); writing no video");
    video_failed_ = true;
    return;
  }
  const std::vector<std::string> args = {ffmpeg,      "-loglevel",
                                         "error",     "-y",
                                         "-f",        "rawvideo",
                                         "-pix_fmt",  "rgb24",
                                         "-s",        std::to_string(w) + "x" + std::to_string(h),
                                         "-r",        std::to_string(p_.fps),
                                         "-i",        "-",
                                         "-vf",       "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                         "-pix_fmt",  "yuv420p",
                                         video_path()};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    spdlog::warn("render.video: cannot create a pipe to ffmpeg ({}); writing no video", std::strerror(errno));
    video_failed_ = true;
    return;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);  // the read end becomes ffmpeg's stdin
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSID);
  const int rc = posix_spawn(&pid_, ffmpeg.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    spdlog::warn("render.video: could not start {} ({}); writing no video", ffmpeg, std::strerror(rc));
    video_failed_ = true;
    return;
  }
  pipe_ = fdopen(fds[1], "w");
  if (!pipe_) {
    ::close(fds[1]);
    finish();
    video_failed_ = true;
    return;
  }
  w_ = w, h_ = h;
}

void HeadlessOutput::add(const Image<uchar3>& frame) {
  if (p_.write_frames) write_png_rgb(dir_ + "/frames/" + numbered(frames_) + ".png", frame);
  if (p_.video && !pipe_ && !video_failed_) open_video(frame.width(), frame.height());
  if (pipe_) {
    if (frame.width() != w_ || frame.height() != h_)
      throw Error("render.video: frame size changed from " + std::to_string(w_) + "x" + std::to_string(h_) + " to " +
                  std::to_string(frame.width()) + "x" + std::to_string(frame.height()));
    const std::vector<uchar3> px = frame.to_host();
    if (std::fwrite(px.data(), sizeof(uchar3), px.size(), pipe_) != px.size())
      throw Error("render.video: ffmpeg stopped accepting frames (" + std::string(std::strerror(errno)) + ", writing " +
                  video_path() + ")");
  }
  ++frames_;
}

void HeadlessOutput::add(Renderer& r) {
  if (p_.stage_images)
    for (const StageImage& s : r.stage_images())
      write_png_rgb(dir_ + "/stages/" + numbered(frames_) + "_" + s.name + ".png", s.image);
  if (p_.write_frames || p_.video) add(r.read_frame());
  else ++frames_;
}

void HeadlessOutput::finish() {
  if (pipe_) std::fclose(pipe_);  // ffmpeg sees the end of its input and finishes the file
  pipe_ = nullptr;
  if (pid_ <= 0) return;
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error("render.video: ffmpeg failed (" +
                (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                   : "killed by signal " + std::to_string(WTERMSIG(status))) +
                ") writing " + video_path());
}

}  // namespace seamless
