// `seamless bench recon`: allocate + fuse + raycast per frame on TUM frames (--data) or the
// synthetic room, at the configured voxel size (5 mm by default), with per-stage medians.
#include <spdlog/spdlog.h>

#include <memory>

#include "app/bench_cases.hpp"
#include "core/error.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

namespace {
struct ReconFrames {
  std::vector<Image<float>> depth;
  std::vector<Image<uchar3>> rgb;
  std::vector<SE3> pose;
  Intrinsics K;
};

// Frames with known poses, uploaded to the device once.
std::shared_ptr<ReconFrames> load_frames(const BenchOptions& o, int max_frames) {
  InputParams in;
  if (!o.data_dir.empty()) {
    in.source = "tum";
    in.path = o.data_dir;
  }
  auto src = make_source(in, o.device);
  auto f = std::make_shared<ReconFrames>();
  f->K = src->intrinsics();
  RgbdFrame fr;
  SE3 first_inv = SE3::identity();
  while (static_cast<int>(f->depth.size()) < max_frames && src->next(fr)) {
    if (!fr.ground_truth) continue;
    if (f->pose.empty()) first_inv = fr.ground_truth->inverse();
    f->depth.push_back(fr.depth.clone(o.device));
    f->rgb.push_back(fr.rgb.clone(o.device));
    f->pose.push_back(first_inv * *fr.ground_truth);
  }
  if (f->depth.empty()) throw Error("bench recon: no frames with ground-truth poses in " + src->name());
  return f;
}
}  // namespace

std::vector<BenchCase> make_recon_bench(const BenchOptions& o) {
  auto frames = load_frames(o, 40);
  auto maps = std::make_shared<RaycastMaps>();
  std::vector<BenchCase> cases;
  for (const char* layout : {"hash", "dense"}) {
    VolumeParams vp;
    vp.layout = layout;
    if (vp.layout == "dense") vp.voxel_size = 0.01f;  // 512^3 at 5 mm would be 1.6 GB; 4 m / 1 cm
    auto vol = std::shared_ptr<Volume>(make_volume(vp, o.device).release());
    auto timer = std::make_shared<StageTimer>(o.device);
    auto next = std::make_shared<std::size_t>(0);
    // One step = one frame: allocate + fuse + raycast of the next recorded frame (cycling).
    auto step = [=] {
      std::size_t i = (*next)++ % frames->depth.size();
      vol->integrate(frames->depth[i], frames->rgb[i], frames->K, frames->pose[i], timer.get());
      vol->raycast(frames->K, frames->pose[i], *maps, timer.get());
      timer->end_frame(static_cast<std::int64_t>(*next));
    };
    std::string detail = std::string(layout) + ", voxel " + std::to_string(static_cast<int>(vp.voxel_size * 1000)) +
                         " mm, " + std::to_string(frames->depth.size()) + " frames cycled";
    auto report = [timer, vol] {
      VolumeStats s = vol->stats();
      std::string r = "stage medians (ms):";
      for (const char* st : {"allocate", "visible", "fuse", "remove_empty", "raycast_splat", "raycast"})
        if (double m = timer->median_ms(st); m > 0) r += std::string(" ") + st + " " + std::to_string(m);
      return r + "; blocks " + std::to_string(s.allocated_blocks) + ", " + std::to_string(s.bytes_per_block) +
             " bytes/block";
    };
    cases.push_back({std::string("frame_") + layout, step, detail, report});
  }
  return cases;
}

}  // namespace seamless::app
