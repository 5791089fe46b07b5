#include "app/pipeline.hpp"

#include <spdlog/spdlog.h>

#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "recon/ply.hpp"

namespace seamless::app {

namespace {
TrackSequenceParams tracking_params(const Experiment& e) {
  TrackSequenceParams p;
  p.tracker = e.tracker;
  p.preprocess = e.preprocess;
  p.volume = e.volume;
  p.max_frames = e.frames;
  p.write_files = e.output.write_trajectory;
  return p;
}

void log_volume(const VolumeStats& s) {
  spdlog::info("volume: {} blocks of {} bytes ({:.1f} MiB voxels, {:.1f} MiB on the device), hash fill {:.1f}%, "
               "{} failed insertions, {} retries",
               s.allocated_blocks, s.bytes_per_block, s.voxel_bytes / 1048576.0, s.device_bytes / 1048576.0,
               100 * s.hash_fill, s.failed_insertions, s.retries);
}
}  // namespace

ScanResult scan(RunContext& ctx, bool with_volume) {
  const Experiment& e = ctx.experiment();
  require_tracker(e.tracker.kind);
  auto source = make_source(e.input, ctx.device());
  ScanResult r;
  if (with_volume) r.volume = make_volume(e.volume, ctx.device());

  std::int64_t total = e.frames > 0 ? e.frames : source->size().value_or(0);
  Progress progress("scan", total);
  std::int64_t n = 0;
  auto on_frame = [&](const RgbdFrame&, const FrameRecord& rec) { progress.update(++n, to_string(rec.result.status)); };
  r.tracking = track_sequence(*source, tracking_params(e), ctx.device(), ctx.out_dir(), r.volume.get(), on_frame);
  progress.finish();
  for (const FrameRecord& f : r.tracking.frames) {
    ctx.timer().add(f.frame, "preprocess", f.preprocess_ms);
    ctx.timer().add(f.frame, "track", f.track_ms);
    ctx.timer().add(f.frame, "fuse", f.fuse_ms);
    ctx.timer().add(f.frame, "frame", f.frame_ms);
  }
  spdlog::info("{} frames from {} ({} unreadable, skipped); {} lost by tracking; median track {:.3f} ms, frame {:.3f} ms",
               r.tracking.frames.size(), source->name(), source->skipped_frames(), r.tracking.lost_frames,
               r.tracking.median_track_ms, r.tracking.median_frame_ms);
  if (r.volume) {
    log_volume(r.volume->stats());
    if (e.output.write_mesh) {
      Mesh m = r.volume->extract_mesh();
      write_ply(ctx.out_path("mesh.ply"), m);
      spdlog::info("mesh.ply: {} vertices, {} triangles", m.positions.size(), m.triangles.size());
    }
  }
  return r;
}

}  // namespace seamless::app
