// Render section (`render:`): window / headless output, what to draw and what to write.
#pragma once
#include <string>

#include "core/params.hpp"

namespace seamless {

struct RenderParams {
  std::string mode = "none";
  int width = 1280;
  int height = 720;
  std::string view = "mesh";          // mesh: coloured scene mesh; kinect: live RGB with depth occlusion
  std::string fluid = "ssfr";         // screen-space fluid rendering (van der Laan 2009) or raw particles
  bool write_frames = false;
  bool video = false;
  bool stage_images = false;

  template <class V> void visit(V& v) {
    v("mode", mode, "window, headless (PNGs) or no rendering", Choices{"window", "headless", "none"});
    v("width", width, "framebuffer width, pixels", Range{16, 16384});
    v("height", height, "framebuffer height, pixels", Range{16, 16384});
    v("view", view, "scene as reconstructed mesh or as the Kinect's view", Choices{"mesh", "kinect"});
    v("fluid", fluid, "fluid drawing", Choices{"ssfr", "particles"});
    v("write_frames", write_frames, "write each rendered frame as PNG into the output folder");
    v("video", video, "encode the frames into a video (needs ffmpeg)");
    v("stage_images", stage_images, "also write the intermediate SSFR stages (depth, blur, thickness)");
  }
};

}  // namespace seamless
