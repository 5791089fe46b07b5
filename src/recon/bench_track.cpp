#include "recon/bench_track.hpp"

#include <memory>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "kernels/recon/rgbd.hpp"
#include "recon/tracker.hpp"
#include "recon/tracker_sequence.hpp"

namespace seamless {

namespace {

std::vector<RgbdFrame> first_frames(const std::string& data_dir, int n, Device device) {
  InputParams in;
  if (data_dir.empty()) {
    in.source = InputSource::synthetic;
    in.synthetic.frames = n;
  } else {
    in.source = InputSource::tum;
    in.path = data_dir;
    in.max_frames = n;
  }
  auto src = make_source(in, device);  // frames in page-locked memory for CUDA, as a GPU run gets them
  std::vector<RgbdFrame> out(n);
  for (auto& f : out)
    if (!src->next(f)) throw Error("the benchmark needs " + std::to_string(n) + " frames of " + src->name());
  return out;
}

// A device pyramid of a host frame, with intensity for the RGB-D tracker.
std::shared_ptr<FramePyramid> pyramid(const RgbdFrame& f, Device d) {
  auto p = std::make_shared<FramePyramid>(d, f.intrinsics, 3);
  Image<float> depth = f.depth.clone(d), inten(f.depth.width(), f.depth.height(), d);
  Image<uchar3> rgb = f.rgb.clone(d);
  with_exec(d, [&]<class E>(const E& ex) { kernels::Rgbd<E>::rgb_to_intensity(ex, rgb.cview(), inten.view()); });
  p->build(depth, &inten, PreprocessParams{});
  return p;
}

TrackBenchCase align_case(const std::string& kind, const std::vector<RgbdFrame>& f, Device d) {
  TrackerParams tp;
  tp.kind = kind;
  tp.mode = TrackingMode::frame_to_frame;
  tp.stop_translation = tp.stop_rotation_deg = 0.f;  // every iteration of 10/5/4, as the goal counts them
  auto tracker = std::make_shared<Tracker>(tp, d);
  auto cur = pyramid(f[2], d), prev = pyramid(f[0], d);
  auto ref = std::make_shared<ReferenceMaps>();
  ref->set_from_frame(*prev, SE3::identity());
  return {kind + "_640x480", [=] { tracker->track(*cur, *ref, SE3::identity()); },
          "align two frames 2 apart, 3 levels, 10/5/4 Gauss-Newton iterations"};
}

}  // namespace

std::vector<TrackBenchCase> make_track_bench(Device device, const std::string& data_dir) {
  auto frames = std::make_shared<std::vector<RgbdFrame>>(first_frames(data_dir, 3, device));
  std::vector<TrackBenchCase> cases = {align_case("icp", *frames, device), align_case("rgbd", *frames, device)};
  TrackSequenceParams p;  // frame-to-model ICP, 5 mm voxels: the default pipeline
  p.tracker.gravity = GravitySource::none;
  auto session = std::make_shared<TrackingSession>(p, device, (*frames)[0].intrinsics);
  session->process((*frames)[0]);  // the first frame only defines the world; later calls track
  auto i = std::make_shared<std::size_t>(1);
  cases.push_back(
      {"frame_640x480",
       [=] {
         session->process((*frames)[*i]);
         *i = *i % 2 + 1;  // alternate frames 1 and 2 around frame 0's model
       },
       "upload + preprocess + frame-to-model ICP (10/5/4, stopping at the default step thresholds) + fuse + "
       "raycast, 5 mm hash volume"});
  return cases;
}

}  // namespace seamless
