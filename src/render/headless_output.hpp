// Headless front end's output: frames/NNNNNN.png, the fluid stage images, and an MP4 encoded by
// piping raw RGB frames to ffmpeg when it is installed (and asked for).
//
//   HeadlessOutput out(run_dir, params);   // params.write_frames, params.video, params.fps
//   for (...) { r.draw(list, cam); out.add(r); }
//   out.finish();                          // closes the video; also done by the destructor
#pragma once
#include <sys/types.h>
#include <cstdint>

#include <cstdio>
#include <string>

#include "core/buffer.hpp"
#include "core/math.hpp"
#include "render/render_params.hpp"

namespace seamless {

class Renderer;

class HeadlessOutput {
 public:
  // Frames go to <dir>/frames/, stages to <dir>/stages/, the video to <dir>/video.mp4.
  HeadlessOutput(const std::string& dir, const RenderParams& params);
  ~HeadlessOutput();
  HeadlessOutput(const HeadlessOutput&) = delete;
  HeadlessOutput& operator=(const HeadlessOutput&) = delete;

  // Reads the renderer's last frame (and its stage images if any) and writes what was asked.
  void add(Renderer& r);
  void add(const Image<uchar3>& frame);
  void finish();

  std::int64_t frames() const { return frames_; }
  bool video_open() const { return pipe_ != nullptr; }
  std::string video_path() const { return dir_ + "/video.mp4"; }

 private:
  void open_video(int w, int h);
  std::string dir_;
  RenderParams p_;
  std::int64_t frames_ = 0;
  FILE* pipe_ = nullptr;  // ffmpeg's stdin
  pid_t pid_ = -1;        // ffmpeg's process
  int w_ = 0, h_ = 0;
  bool video_failed_ = false;
};

// The ffmpeg executable on PATH, or "" when there is none.
std::string find_ffmpeg();

}  // namespace seamless
