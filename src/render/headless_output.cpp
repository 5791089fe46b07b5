#include "render/headless_output.hpp"

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "io/png_io.hpp"
#include "render/renderer.hpp"

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
void HeadlessOutput::open_video(int w, int h) {
  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) {
    spdlog::warn("render.video: ffmpeg is not installed (apt-get install ffmpeg); writing no video");
    video_failed_ = true;
    return;
  }
  // setsid: ffmpeg in a session of its own, so that a Ctrl-C meant for the run (which then
  // finishes its frame and writes its outputs) does not kill the encoder mid-file.
  const std::string cmd = "exec setsid -w '" + ffmpeg + "' -loglevel error -y -f rawvideo -pix_fmt rgb24 -s " +
                          std::to_string(w) + "x" + std::to_string(h) + " -r " + std::to_string(p_.fps) +
                          " -i - -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -pix_fmt yuv420p '" + video_path() + "'";
  pipe_ = popen(cmd.c_str(), "w");
  if (!pipe_) {
    spdlog::warn("render.video: could not start ffmpeg ({}); writing no video", cmd);
    video_failed_ = true;
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
      throw Error("render.video: ffmpeg stopped accepting frames (writing " + video_path() + ")");
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
  if (!pipe_) return;
  const int rc = pclose(pipe_);
  pipe_ = nullptr;
  if (rc != 0)
    throw Error("render.video: ffmpeg failed (exit status " + std::to_string(rc) + ") writing " + video_path());
}

}  // namespace seamless
