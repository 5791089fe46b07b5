// `seamless bench recon`: allocate + fuse + raycast per frame on TUM frames (--data) or the
// synthetic room, at the configured voxel size (5 mm by default), with per-stage medians. The
// frame step and the report are recon/bench_recon's ReconBench (one code path with bench_recon()).
#include <spdlog/spdlog.h>

#include <memory>

#include "app/bench_cases.hpp"
#include "core/error.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "recon/bench_recon.hpp"

namespace seamless::app {

namespace {
// Frames with known poses (relative to the first), on the host.
std::vector<ReconFrame> load_frames(const BenchOptions& o, int max_frames, Intrinsics* K) {
  InputParams in;
  if (!o.data_dir.empty()) {
    in.source = InputSource::tum;
    in.path = o.data_dir;
  }
  auto src = make_source(in, o.device);
  *K = src->intrinsics();
  std::vector<ReconFrame> frames;
  RgbdFrame fr;
  SE3 first_inv = SE3::identity();
  while (static_cast<int>(frames.size()) < max_frames && src->next(fr)) {
    if (!fr.ground_truth) continue;
    if (frames.empty()) first_inv = fr.ground_truth->inverse();
    frames.push_back({fr.depth.clone(Device::CPU), fr.rgb.clone(Device::CPU), first_inv * *fr.ground_truth});
  }
  if (frames.empty()) throw Error("bench recon: no frames with ground-truth poses in " + src->name());
  return frames;
}
}  // namespace

std::vector<BenchCase> make_recon_bench(const BenchOptions& o) {
  Intrinsics K;
  const std::vector<ReconFrame> frames = load_frames(o, 40, &K);
  std::vector<BenchCase> cases;
  for (VolumeLayout layout : {VolumeLayout::hash, VolumeLayout::dense}) {
    VolumeParams vp;
    vp.layout = layout;
    if (vp.layout == VolumeLayout::dense) vp.voxel_size = 0.01f;  // 512^3 at 5 mm would be 1.6 GB; 4 m / 1 cm
    auto bench = std::make_shared<ReconBench>(frames, K, vp, o.device);
    std::string detail = std::string(enum_name(layout)) + ", voxel " +
                         std::to_string(static_cast<int>(vp.voxel_size * 1000)) + " mm, " +
                         std::to_string(frames.size()) + " frames cycled";
    // One step = one frame: allocate + fuse + raycast of the next recorded frame (cycling).
    cases.push_back({std::string("frame_") + enum_name(layout), [bench] { bench->step(); }, detail,
                     [bench] { return bench->report(); }});
  }
  return cases;
}

}  // namespace seamless::app
